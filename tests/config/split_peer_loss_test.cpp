// The split of config/split/ losing its vision daemon: killed mid-run (SIGKILL, no goodbye),
// the control daemon keeps its loops and its simulated robot running (its drivers' devices
// answer every cycle, no fault), marks the bridged sheet_state stale (its bridge reports
// degraded, the port gets no value, the score no frame), and takes a new vision daemon's
// model as soon as it publishes: that model starts where every model starts and finds the
// world's sheet again from the images of the truth the control daemon still sends.
#include <doctest/doctest.h>

#include <string>

#include "creased_child.h"

using namespace crease::test;
using namespace std::chrono_literals;

namespace {

// Polls PRED every 100 ms for up to 60 s (a hang guard for a loaded machine, not a figure).
template <class P>
bool eventually(P pred) {
  for (int i = 0; i < 600; ++i) {
    if (pred()) return true;
    std::this_thread::sleep_for(100ms);
  }
  return false;
}

// The per-second tracking errors the control daemon printed after its first FROM seconds.
std::vector<double> seconds_after(const Creased& c, std::size_t from) {
  const std::vector<double> all = tracking_per_second(c.output());
  return all.size() > from ? std::vector<double>(all.begin() + static_cast<long>(from), all.end())
                           : std::vector<double>{};
}

// A second whose model frames were within 5 mm of the truth (the sheet found and held).
bool found(const std::vector<double>& seconds) {
  for (double e : seconds)
    if (e >= 0 && e < 5.0) return true;
  return false;
}

}  // namespace

TEST_CASE("config/split: the vision daemon killed and restarted; the control daemon runs on, stale, then resumes") {
  TempDir tmp;
  const std::string d = std::to_string(test_domain());
  const std::vector<std::string> vision_args = {"--duration", "120", "--no-progress", "--set", "bridge.domain=" + d,
                                                "--set", "truth.domain=" + d};
  Creased control("control", tmp.path, "split/control.yaml", {"--duration", "120", "--set", "bridge.domain=" + d});
  REQUIRE(control.request("status"));
  auto vision = std::make_unique<Creased>("vision1", tmp.path, "split/vision.yaml", vision_args);
  INFO("control:\n" << control.output());

  // Tracking: the model's frames arrive and one second's are within 5 mm of the world's sheet.
  REQUIRE(eventually([&] { return found(seconds_after(control, 0)); }));
  CHECK(control.entry("plugins", "bridge")["health"] == "ok");

  // Killed. Its writers' leases (500 ms) lapse: stale, the bridge degraded, no more writes.
  vision->kill();
  REQUIRE(eventually([&] { return control.entry("plugins", "bridge")["health"] == "degraded"; }));
  const auto at_loss = control.request("status");
  REQUIRE(at_loss);
  const std::uint64_t writes = number(control.entry("ports", "sheet_state"), "writes");
  const std::uint64_t control_cycles = number(control.entry("loops", "control"), "cycles");
  const std::uint64_t world_cycles = number(control.entry("loops", "world"), "cycles");
  const std::size_t seconds_before = tracking_per_second(control.output()).size();
  // Two seconds of progress lines without the peer.
  REQUIRE(eventually([&] { return tracking_per_second(control.output()).size() >= seconds_before + 2; }));
  CHECK(number(control.entry("ports", "sheet_state"), "writes") == writes);  // nothing old written as new
  const std::vector<double> outage = seconds_after(control, seconds_before);
  REQUIRE(outage.size() >= 2);
  CHECK(outage.back() == -1.0);  // "no model frames (this second)": the score adds nothing
  CHECK(control.entry("plugins", "bridge")["health"] == "degraded");
  // Its loops ran on, and in step: without its peer no driver's device (answering in the
  // world's loop, half a period behind) went silent for the 50 cycles a device fault takes, and
  // nothing faulted. (A vision daemon starting up, building its renderer and locking its
  // memory, can delay the world's loop on a loaded 2-core machine that much: not counted here.)
  CHECK(number(control.entry("loops", "control"), "cycles") > control_cycles + 500);
  CHECK(number(control.entry("loops", "world"), "cycles") > world_cycles + 500);
  auto status = control.request("status");
  REQUIRE(status);
  CHECK((*status)["faults"] == 0);
  CHECK((*status)["device_faults"] == (*at_loss)["device_faults"]);
  CHECK((*status)["devices_in_fault"] == 0);
  const auto plugins = control.request("plugins");
  REQUIRE(plugins);
  for (const auto& p : *plugins) {
    CAPTURE(p["name"]);
    CHECK(p["state"] == "active");
  }

  // A new vision daemon: fresh again, and its model (starting from scratch) finds the sheet.
  vision = std::make_unique<Creased>("vision2", tmp.path, "split/vision.yaml", vision_args);
  REQUIRE(eventually([&] { return number(control.entry("ports", "sheet_state"), "writes") > writes; }));
  REQUIRE(eventually([&] { return control.entry("plugins", "bridge")["health"] == "ok"; }));
  const std::size_t seconds_back = tracking_per_second(control.output()).size();
  REQUIRE(eventually([&] { return found(seconds_after(control, seconds_back)); }));
  std::string seen;
  for (double e : tracking_per_second(control.output())) seen += (e < 0 ? std::string("-") : std::to_string(e)) + " ";
  MESSAGE("the control daemon's tracking error per second (mm; - : no model frame): " << seen);

  CHECK(vision->stop() == 0);
  CHECK(control.stop() == 0);
  const std::string out = control.output();
  CHECK(out.find("  faults: 0, device faults: ") != std::string::npos);
}
