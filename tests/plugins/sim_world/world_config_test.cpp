// sim_world's table and sheet parameters: the table's extent (an edge to overhang) read as given,
// null sides without an edge, the sheet's turn; every malformed value a ConfigError naming file,
// line and key; the world_shapes rate (the truth's by default).
#include "plugins/sim_world/world_config.h"

#include <doctest/doctest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "core/errors.h"
#include "drivers/simdevice/sim_robot.h"

using namespace crease;
using crease::world::read_world_config;
using crease::world::WorldParams;

namespace {

world::WorldPluginConfig read(const std::string& extra) {
  const std::string yaml = "robot: " CREASE_SOURCE_DIR "/config/robot/crease_robot.yaml\n" + extra;
  return read_world_config(Params(YAML::Load(yaml), "sim.yaml", "world.params"));
}

std::string error_of(const std::string& extra) {
  try {
    (void)read(extra);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("table_extent_mm: absent a plane, given the slab's sides, null a side without an edge") {
  const auto plane = read("").world.table_extent_mm;
  for (double v : {plane[0], plane[2]}) CHECK(v == -WorldParams::kNoEdge);
  for (double v : {plane[1], plane[3]}) CHECK(v == WorldParams::kNoEdge);

  const auto e = read("table_extent_mm: [-400, 400, -175, null]\n").world.table_extent_mm;
  CHECK(e[0] == -400.0);
  CHECK(e[1] == 400.0);
  CHECK(e[2] == -175.0);
  CHECK(e[3] == WorldParams::kNoEdge);
}

TEST_CASE(
    "table_edge_radius_mm: 5 mm unless given, 0-20 mm; out of range it names file, line and key") {
  CHECK(read("").world.table_edge_radius_mm == 5.0);
  CHECK(read("table_edge_radius_mm: 0\n").world.table_edge_radius_mm == 0.0);
  const std::string e = error_of("table_edge_radius_mm: -1\n");
  CHECK(e.find("sim.yaml:2") != std::string::npos);
  CHECK(e.find("table_edge_radius_mm") != std::string::npos);
}

TEST_CASE("table_extent_mm: a malformed extent names file, line and key") {
  for (const char* bad : {"table_extent_mm: [1, 2, 3]\n", "table_extent_mm: 5\n", "table_extent_mm: [0, x, 0, 1]\n",
                          "table_extent_mm: [0, 1e9, 0, 1]\n", "table_extent_mm: [10, 0, 0, 1]\n"}) {
    const std::string e = error_of(bad);
    INFO(bad << " -> " << e);
    CHECK(e.find("sim.yaml:2") != std::string::npos);
    CHECK(e.find("table_extent_mm") != std::string::npos);
  }
}

TEST_CASE("sheet_turn_deg turns the world's sheet grid; out of range it names file, line and key") {
  CHECK(read("").world.sheet.grid.turn_deg == 0.0);
  CHECK(read("sheet_turn_deg: 180\n").world.sheet.grid.turn_deg == 180.0);
  const std::string e = error_of("sheet_turn_deg: 181\n");
  CHECK(e.find("sim.yaml:2") != std::string::npos);
  CHECK(e.find("sheet_turn_deg") != std::string::npos);
}

TEST_CASE(
    "substeps: the sheet's 2 by default, as given within 1-16; out of range it names file, line "
    "and key") {
  CHECK(read("").world.sheet.solver.substeps == 2);
  CHECK(read("substeps: 4\n").world.sheet.solver.substeps == 4);
  for (const char* bad : {"substeps: 0\n", "substeps: 17\n", "substeps: two\n"}) {
    const std::string e = error_of(bad);
    INFO(bad << " -> " << e);
    CHECK(e.find("sim.yaml:2") != std::string::npos);
    CHECK(e.find("substeps") != std::string::npos);
  }
}

TEST_CASE(
    "max_strain: off (0) by default, as given within 0-0.2; out of range it names file, line and "
    "key") {
  CHECK(read("").world.sheet.solver.max_strain == 0.0);
  CHECK(read("max_strain: 0.01\n").world.sheet.solver.max_strain == 0.01);
  CHECK(read("max_strain: 0.02\n").world.sheet.solver.max_strain == 0.02);
  for (const char* bad : {"max_strain: -0.01\n", "max_strain: 0.3\n", "max_strain: stiff\n"}) {
    const std::string e = error_of(bad);
    INFO(bad << " -> " << e);
    CHECK(e.find("sim.yaml:2") != std::string::npos);
    CHECK(e.find("max_strain") != std::string::npos);
  }
}

// The devices' command watchdog: a real device's 20 ms unless the configuration says
// (config/sim.yaml: 100, as the drivers' tolerance of the shared machine's stalls); the simulated
// robot takes it.
TEST_CASE(
    "device_watchdog_ms: 20 by default, the devices take what is given; out of range names file, "
    "line and key") {
  CHECK(read("").device_watchdog_ms == 20.0);
  CHECK(read("device_watchdog_ms: 100\n").device_watchdog_ms == 100.0);
  const std::string e = error_of("device_watchdog_ms: 0\n");
  CHECK(e.find("sim.yaml:2") != std::string::npos);
  CHECK(e.find("device_watchdog_ms") != std::string::npos);
  crease::drivers::sim::SimRobotConfig rc;
  rc.prefix = "crease-t-wd-" + std::to_string(::getpid());
  rc.watchdog_ns = 100'000'000;
  crease::drivers::sim::SimRobot robot(rc);
  for (int i = 0; i < crease::drivers::sim::SimRobot::kDevices; ++i)
    CHECK(robot.device(i).watchdog_ns() == 100'000'000);
}

TEST_CASE("faults: off unless asked; drawn from the world's seed unless fault_seed says; out of range names file, line and key") {
  CHECK_FALSE(read("").faults);
  const auto on = read("seed: 9\nfaults: true\nfault_drop: 0.01\nfault_bus_off: false\n");
  CHECK(on.faults);
  CHECK(on.bus_faults.seed == 9);
  CHECK(on.bus_faults.drop == doctest::Approx(0.01));
  CHECK_FALSE(on.bus_faults.bus_off);
  CHECK(read("seed: 9\nfaults: true\nfault_seed: 4\n").bus_faults.seed == 4);
  for (const char* bad : {"fault_drop: 2\n", "fault_delay_ms: -1\n", "fault_from_s: 10\nfault_to_s: 5\n", "faults: maybe\n"}) {
    const std::string e = error_of(bad);
    INFO(bad << " -> " << e);
    CHECK(e.find("sim.yaml:") != std::string::npos);
    CHECK(e.find("fault") != std::string::npos);
  }
}

TEST_CASE(
    "shapes_every_steps: the truth's rate unless given; out of range an error naming the key") {
  CHECK(read("").shapes_every_steps == 16);
  CHECK(read("truth_every_steps: 4\n").shapes_every_steps == 4);
  CHECK(read("truth_every_steps: 4\nshapes_every_steps: 33\n").shapes_every_steps == 33);
  CHECK(error_of("shapes_every_steps: 0\n").find("world.params.shapes_every_steps") !=
        std::string::npos);
}
