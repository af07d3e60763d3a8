// config/split/control.yaml and config/split/vision.yaml validate and build in one process, on
// a DDS domain of this test's own; then both daemons' loops run here, their cycles interleaved
// on this thread marked RT, with the configurations' real parameters: once the world's sheet has
// crossed to the vision daemon's cameras (so that every plugin does its full work) not one heap
// allocation is allowed. As tests/config/shipped_config_test.cpp does for config/sim.yaml.
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <string>
#include <thread>

#include "core/config/daemon_config.h"
#include "core/daemon/daemon.h"
#include "core/port_types/sheet_state.h"
#include "rt/alloc_guard.h"
#include "sim_cycles.h"

using crease::test::run_cycles;

namespace {

struct Side {
  std::unique_ptr<crease::daemon::Daemon> daemon;
  std::int64_t now = 1'000'000'000;
  std::map<const crease::Loop*, std::uint64_t> cycles;

  Side(const char* file, const std::vector<std::string>& bridges) {
    auto cfg = crease::config::load_daemon_config(std::string(CREASE_SOURCE_DIR) + "/config/split/" + file);
    const std::string domain = std::to_string(1 + ::getpid() % 200);
    for (const std::string& b : bridges) crease::config::override_param(cfg, b + ".domain=" + domain);
    crease::daemon::Options opts;
    opts.plugin_dirs = {CREASE_PLUGIN_DIR};
    daemon = std::make_unique<crease::daemon::Daemon>(std::move(cfg), opts);
  }
  crease::PluginHost& host() { return daemon->host(); }
};

// Both sides' cycles for `seconds` of simulated time, in slices of 50 ms each.
void run_both(Side& a, Side& b, double seconds) {
  for (double t = 0; t < seconds; t += 0.05) {
    run_cycles(a.host(), 0.05, a.now, a.cycles);
    run_cycles(b.host(), 0.05, b.now, b.cycles);
  }
}

}  // namespace

TEST_CASE("config/split: both daemons' steady-state cycles allocate nothing") {
  Side control("control.yaml", {"bridge"});
  Side vision("vision.yaml", {"bridge", "truth"});
  REQUIRE_FALSE(control.host().instances().empty());
  REQUIRE_FALSE(vision.host().instances().empty());

  // Warm-up (first frames, caches, lazy buffers), until the world's sheet is in the vision
  // daemon's port and the model's in the control daemon's: DDS carries them in real time, on
  // its own threads, while the cycles here run in simulated time.
  const auto has = [](Side& s, const char* port) {
    const crease::rt::LatestChannel* ch = s.host().ports().find_latest(port);
    return ch != nullptr && ch->sequence() > 0;
  };
  run_both(control, vision, 2.0);
  for (int i = 0; i < 200 && !(has(vision, "sheet_truth") && has(control, "sheet_state")); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // a hang guard, not a figure
    run_both(control, vision, 0.1);
  }
  REQUIRE(has(vision, "sheet_truth"));
  REQUIRE(has(control, "sheet_state"));
  run_both(control, vision, 1.0);  // the cameras render the truth, the model moves to it

  const auto before = crease::rt::rt_allocation_count();
  run_both(control, vision, 3.0);
  const auto allocations = crease::rt::rt_allocation_count() - before;
  CHECK(allocations == 0);
  for (Side* s : {&control, &vision}) {
    for (const auto& i : s->host().instances()) {
      CAPTURE(i.name);
      CHECK(i.state == crease::RunState::active);  // no plugin faulted on the way
      CHECK(i.stats->updates.load() > 0);
      CHECK(i.stats->rt_allocations.load() == 0);
    }
  }
}
