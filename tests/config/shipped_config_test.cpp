// config/sim.yaml validates and builds; then every loop's cycles run here, on a thread marked
// RT, with the plugins' real parameters: after a warm-up, not one heap allocation is allowed.
// This covers every plugin the main job ships, whatever joins sim.yaml later.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <string>

#include <yaml-cpp/yaml.h>

#include "core/config/daemon_config.h"
#include "core/daemon/daemon.h"
#include "rt/alloc_guard.h"
#include "sim_cycles.h"

using crease::test::run_cycles;

TEST_CASE("config/sim.yaml: every plugin's steady-state cycles allocate nothing") {
  auto cfg = crease::config::load_daemon_config(CREASE_SOURCE_DIR "/config/sim.yaml");
  // The sheet model with each of its couplings (how the key-points pull it): as shipped
  // (springs) and with the other one (tests/plugins/sheet_model/sheet_runner_test.cpp shows
  // what each one does).
  std::string coupling;
  SUBCASE("as shipped") {}
  SUBCASE("coupling: keypoints") { coupling = "keypoints"; }
  if (!coupling.empty()) {
    int sheets = 0;
    for (auto& pc : cfg.plugins) {
      if (pc.library != "sheet_model") continue;
      pc.params["coupling"] = coupling;
      ++sheets;
    }
    REQUIRE(sheets == 1);
  }
  crease::daemon::Options opts;
  opts.plugin_dirs = {CREASE_PLUGIN_DIR};
  crease::daemon::Daemon daemon(std::move(cfg), opts);
  crease::PluginHost& host = daemon.host();
  REQUIRE_FALSE(host.instances().empty());

  std::int64_t now = 1'000'000'000;
  std::map<const crease::Loop*, std::uint64_t> cycles;
  run_cycles(host, 2.0, now, cycles);  // warm-up: first frames, caches, lazy buffers
  const auto before = crease::rt::rt_allocation_count();
  run_cycles(host, 3.0, now, cycles);
  const auto allocations = crease::rt::rt_allocation_count() - before;
  CHECK(allocations == 0);
  for (const auto& i : host.instances()) {
    CAPTURE(i.name);
    CHECK(i.state == crease::RunState::active);  // no plugin faulted on the way
    CHECK(i.stats->updates.load() > 0);
  }
}

TEST_CASE("config/split/control.yaml and config/split/vision.yaml validate: the split of config/sim.yaml") {
  // Their loops and cycles run in tests/config/split_cycles_test.cpp (over DDS: label hil).
  const auto control = crease::config::load_daemon_config(CREASE_SOURCE_DIR "/config/split/control.yaml");
  const auto vision = crease::config::load_daemon_config(CREASE_SOURCE_DIR "/config/split/vision.yaml");
  const auto sim = crease::config::load_daemon_config(CREASE_SOURCE_DIR "/config/sim.yaml");
  // Every instance of config/sim.yaml runs in one of the two, of the same library and loop
  // rate, and with the same parameters but for the paths (one folder deeper here).
  for (const auto& p : sim.plugins) {
    CAPTURE(p.name);
    const auto* c = control.find_plugin(p.name);
    const auto* v = vision.find_plugin(p.name);
    REQUIRE((c != nullptr) != (v != nullptr));
    const auto& split = c != nullptr ? *c : *v;
    CHECK(split.library == p.library);
    CHECK(split.order == p.order);
    CHECK(split.ports == p.ports);
    std::map<std::string, std::string> a, b;
    for (const auto& kv : p.params) a[kv.first.as<std::string>()] = YAML::Dump(kv.second);
    for (const auto& kv : split.params) b[kv.first.as<std::string>()] = YAML::Dump(kv.second);
    for (auto& [k, val] : b)
      if (val.rfind("../", 0) == 0) val = val.substr(3);  // one folder deeper
    CHECK(a == b);
  }
  // The world, drivers and controllers in control; cameras, vision and model in vision.
  for (const char* n : {"world", "hand_r", "hand_l", "arm_r", "arm_l", "contact_r", "force_r", "motion_r", "score"})
    CHECK(control.find_plugin(n) != nullptr);
  for (const char* n : {"cameras", "vision", "sheet"}) CHECK(vision.find_plugin(n) != nullptr);
}

TEST_CASE("config/robot.yaml validates (its plugins need the hardware to configure)") {
  crease::config::LoadOptions o;
  o.check_plugin_dirs_exist = false;
  const auto cfg = crease::config::load_daemon_config(CREASE_SOURCE_DIR "/config/robot.yaml", o);
  CHECK(cfg.loops.size() == 3);
  CHECK(cfg.find_plugin("hand_r") != nullptr);
  CHECK(cfg.safety.on_fault == crease::config::FaultPolicy::stop);
}
