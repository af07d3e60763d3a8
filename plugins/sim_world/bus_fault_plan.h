// The faults of the simulated robot's buses (`sim_world` with `faults: true`; crease-trials
// --faults), drawn from one seed in world time so a trial's faults are the same every run:
// per-frame drops and corruptions on every bus for the whole run, one burst in which one bus
// delivers every frame late, one bus-off of one hand's driver. BusFaultInjector (bus_faults.h)
// applies a plan to the buses. Non-RT.
#pragma once

#include <cstdint>
#include <string>

namespace crease::world {

// The buses in the simulated robot's order (drivers/simdevice/sim_robot.h: hand_r, hand_l, arm_r, arm_l).
inline constexpr int kFaultBuses = 4;
inline constexpr const char* kFaultBusNames[kFaultBuses] = {"hand_r", "hand_l", "arm_r", "arm_l"};

struct BusFaultConfig {
  std::uint64_t seed = 1;
  double drop = 0.002;            // per frame, every bus
  double corrupt = 0.002;         // per frame, every bus: one payload bit flipped
  double delay_burst_s = 0.03;    // the burst's length (world s); 0: none
  double delay_ms = 5.0;          // how late every frame of the burst arrives
  bool bus_off = true;            // one bus-off of a hand's driver
  std::uint32_t host_node = 100;  // the drivers' node id on the buses (hand_driver `host_node`)
  double from_s = 5.0, to_s = 25.0;  // the burst's start and the bus-off lie in this window (world s)
};

// The drawn schedule: which bus has the delay burst and when, which hand's driver goes bus-off
// and when (bus indices: kFaultBusNames).
struct BusFaultPlan {
  BusFaultConfig cfg;
  int delay_bus = 0;
  double delay_at_s = 0;
  int bus_off_bus = 0;  // 0 (hand_r) or 1 (hand_l)
  double bus_off_at_s = 0;
};

[[nodiscard]] BusFaultPlan draw_bus_faults(const BusFaultConfig& cfg);
// One line for the log and the trials' table, e.g. "bus faults (seed 3): drop 0.002, ...".
[[nodiscard]] std::string describe(const BusFaultPlan& plan);

}  // namespace crease::world
