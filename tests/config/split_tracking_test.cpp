// The split of seed 000 (config/split/): the vision daemon (cameras, vision, sheet model) and
// the control daemon (world, drivers, controllers, score) as two creased processes over Cyclone
// DDS on the loopback interface track the world's sheet as config/sim.yaml does in one process.
// The world's sheet lies on the table at the pose its seed drew (seed 1: 15 mm off and turned
// 14 deg from where the model starts): the model must find it from the images the vision
// daemon renders of the truth the control daemon sends, and the error is scored in the control
// daemon, against its own world's truth (never the tracker's belief). The world's arms and hands
// (`world_shapes`) cross with its sheet, for the vision daemon's cameras to draw.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <thread>

#include "creased_child.h"

using namespace crease::test;
using namespace std::chrono_literals;

namespace {

const std::string kVisionSeconds = "12";  // the model frames scored: as many as config/sim.yaml's run below

// The split: control first, then vision for kVisionSeconds; control is stopped once vision has
// ended (no model frame comes after). TRUTH_DOMAIN: the domain of the vision daemon's `truth`
// bridge (the world's sheet and its arms and hands for its cameras); the split's own domain puts
// the world in view. SHAPES_WRITES: how often the vision daemon's `world_shapes` port had been
// written once its truth arrived (or after 5 s without it), 0 when nothing crossed.
TrackingSummary run_split(const TempDir& tmp, int truth_domain, const char* vision_seconds,
                          std::uint64_t* shapes_writes = nullptr) {
  const std::string d = std::to_string(test_domain());
  Creased control("control", tmp.path, "split/control.yaml", {"--duration", "120", "--set", "bridge.domain=" + d});
  REQUIRE(control.request("status"));  // up: its world publishes the truth
  Creased vision("vision", tmp.path, "split/vision.yaml",
                 {"--duration", vision_seconds, "--no-progress", "--set", "bridge.domain=" + d, "--set",
                  "truth.domain=" + std::to_string(truth_domain)});
  const auto writes = [&](const char* port) {
    return number(vision.entry("ports", port), "writes");
  };
  for (int i = 0; i < 50 && writes("sheet_truth") == 0; ++i) std::this_thread::sleep_for(100ms);
  if (shapes_writes != nullptr) *shapes_writes = writes("world_shapes");
  const int vision_rc = vision.wait_exit();
  std::this_thread::sleep_for(500ms);  // the last frames in flight (they would be scored, not lost)
  const int control_rc = control.stop();
  const std::string out = control.output();
  INFO("control:\n" << out);
  INFO("vision:\n" << vision.output());
  CHECK(vision_rc == 0);
  CHECK(control_rc == 0);
  CHECK(out.find("  faults: 0, ") != std::string::npos);  // no plugin faulted
  CHECK(vision.output().find("  faults: 0, ") != std::string::npos);
  const auto s = tracking_summary(out);
  REQUIRE(s);
  return *s;
}

}  // namespace

TEST_CASE("config/split: two daemons over loopback DDS track the world's sheet as config/sim.yaml does") {
  TempDir tmp;
  // The single-process figure of the same run length, on the machine as loaded now.
  TrackingSummary single;
  {
    Creased sim("sim", tmp.path, "sim.yaml", {"--duration", kVisionSeconds});
    REQUIRE(sim.wait_exit() == 0);
    const std::string out = sim.output();
    INFO(out);
    const auto s = tracking_summary(out);
    REQUIRE(s);
    single = *s;
  }
  std::uint64_t shapes = 0;
  const TrackingSummary split = run_split(tmp, test_domain(), kVisionSeconds.c_str(), &shapes);
  // The world's arms and hands crossed with its sheet: the vision daemon's cameras draw them.
  CHECK(shapes > 0);
  MESSAGE("tracking error, mean over the run: one process " << single.mean_mm << " mm (" << single.frames
          << " frames, last " << single.last_mm << " mm); split " << split.mean_mm << " mm (" << split.frames
          << " frames, last " << split.last_mm << " mm)");
  // It found the sheet (a model left where it starts is off by the world's draw to the end) ...
  CHECK(single.last_mm < 5.0);
  CHECK(split.last_mm < 5.0);
  // ... and tracks it as well as one process: the runs' means differ by load (fewer key-points
  // per model frame on a busy machine), about a third between runs of either kind here.
  CHECK(std::abs(split.mean_mm - single.mean_mm) <= 0.5 * std::max(split.mean_mm, single.mean_mm) + 1.0);
  // Every model frame of the vision daemon's run crossed: 60 Hz over its run, less what a
  // loaded machine skips (counted, not replayed) and its start-up; only a stalled link scores
  // fewer than half of one process's.
  CHECK(split.frames > single.frames / 2);
}

TEST_CASE("config/split, failing variant: cameras that do not see the world's sheet leave the model where it starts") {
  // The same split with the vision daemon's truth bridge on another domain: its cameras render
  // no sheet; its model's frames still reach the control daemon, which scores them.
  TempDir tmp;
  std::uint64_t shapes = 0;
  const TrackingSummary blind = run_split(tmp, test_domain() + 1, "8", &shapes);
  CHECK(shapes == 0);
  MESSAGE("blind split: mean " << blind.mean_mm << " mm over " << blind.frames << " frames, last " << blind.last_mm
          << " mm");
  CHECK(blind.frames > 0);
  CHECK(blind.last_mm > 5.0);  // the check the split passes above fails here
}
