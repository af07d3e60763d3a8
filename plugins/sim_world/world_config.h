// The sim_world plugin's parameters (README.md lists them): the world's (WorldParams), the
// robot's parameter file, what the plugin publishes and the simulated robot's buses. Read and
// checked at configure; every error names the configuration's file, line and key. Non-RT.
#pragma once

#include <cstdint>
#include <string>

#include "core/params.h"
#include "plugins/sim_world/bus_fault_plan.h"
#include "plugins/sim_world/world_params.h"

namespace crease::world {

struct WorldPluginConfig {
  std::string robot_yaml;  // `robot`: config/robot/crease_robot.yaml, resolved by Params::get_path
  WorldParams world;
  // `sheet_truth` every truth_every_steps world steps (a SheetState export costs about one
  // world step), with every truth_stride-th node of the world's grid in u and v (2: the 29 x 41
  // world sheet as the tracking model's 15 x 21, which sheet_score compares node by node).
  int truth_every_steps = 16;
  int truth_stride = 1;
  // `world_shapes` (the robot's shapes, for the simulated cameras) every shapes_every_steps world
  // steps, in the same steps as the truth when the two rates are equal; default: the truth's.
  int shapes_every_steps = 16;
  std::string bus_prefix;  // resolved (`auto`: this creased's own, drivers/host/bus_prefix.h)
  std::uint32_t bitrate = 1'000'000, data_bitrate = 5'000'000;
  // `device_watchdog_ms`: the simulated devices' command watchdog (their clock, the world's: a
  // control loop that stalls this long while the world steps on quick-stops the arms and makes
  // the hands safe, as a real device does after 20 ms, the default).
  double device_watchdog_ms = 20.0;
  // `tactile_link`: the taxel matrix's serial link, a Unix socket at simulated_link_path(bus_prefix,
  // this) (drivers/host/bus_prefix.h) for hand_driver's `tactile_device: tactile_r`; empty
  // (`none`): no link.
  std::string tactile_link = "tactile_r";
  // `faults: true`: the buses' faults of bus_faults.h, drawn from the world's seed unless
  // `fault_seed` says otherwise (`fault_drop`, `fault_corrupt`, `fault_delay_ms`,
  // `fault_delay_burst_s`, `fault_bus_off`, `fault_host_node`, `fault_from_s`, `fault_to_s`).
  bool faults = false;
  BusFaultConfig bus_faults;
};

// Throws crease::ConfigError naming file, line and key.
[[nodiscard]] WorldPluginConfig read_world_config(const Params& p);

// The parked pose of each arm (deg, drivers/README.md §4 order) when the parameters give none:
// each index pad 300 mm over the table, facing down, beside the sheet (x = +-230, y = -230 mm),
// turned about the vertical as the half fold's first goal of that arm (config/folds/half.yaml:
// the right's tool x along world +y, the left's 60 deg from +x), every joint at least 25 deg
// inside its limits (the IK's solution with the most margin; tests/config/sim_reach_test.cpp
// checks the pose).
inline constexpr double kParkedArmDeg[2][7] = {{73.3, -60.1, 59.0, 106.0, -54.2, 130.5, -112.6},
                                               {-47.0, -51.1, -59.3, 109.1, 56.1, 131.8, 103.2}};

}  // namespace crease::world
