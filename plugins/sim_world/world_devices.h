// The simulated robot's devices stepped in lockstep with the world (plugins/sim_world): one
// thread, one clock, the world's. Each step:
//   1. every device takes its frames at the world's time (commands, stiffness, SYNCs, NMT) and
//      answers each SYNC at once with what the world's last step left: the hands' joint angles
//      (target + deflection, SimHand external_positions) and the arms' drive positions;
//   2. the hands' commanded targets and stiffness go to World::command_hand_rt (a limp hand,
//      in its safe state or not enabled, holds the angles it had when it went limp with zero
//      stiffness), the arms' drive positions (SimArm's own position profile) to
//      World::command_arm_rt;
//   3. the world steps (1 ms);
//   4. the hands' joint angles the step settled at become what their next status reports.
// So a fingertip's contact in this step is what the hand's next status frame reports, and the
// devices' clocks (device time, watchdogs, heartbeats) are the world's time: a world that falls
// behind the wall clock takes its devices with it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "drivers/simdevice/sim_robot.h"
#include "plugins/sim_world/sim_world.h"

namespace crease::world {

class WorldDevices {
 public:
  // Non-RT: creates the buses and devices (throws std::runtime_error naming a bus that cannot
  // be created); the arms' drives and the hands' reported angles start where WORLD's are.
  // WORLD must outlive this.
  WorldDevices(World& world, drivers::sim::SimRobotConfig cfg);

  // One lockstep step: devices, commands, the world's step, the angles to report. RT.
  void step_rt() noexcept;

  // The devices' time of the last step: a fixed epoch plus the world's time (ns).
  [[nodiscard]] std::int64_t device_time_ns() const noexcept { return device_ns_; }
  [[nodiscard]] drivers::sim::SimRobot& robot() noexcept { return *robot_; }

  static constexpr std::int64_t kEpochNs = 1'000'000'000;  // device clocks start here, not at 0

 private:
  void report_hand_angles_rt() noexcept;

  World& world_;
  std::unique_ptr<drivers::sim::SimRobot> robot_;
  std::int64_t device_ns_ = kEpochNs;
  std::array<bool, robot::kSides> limp_{};
  std::array<World::HandJoints, robot::kSides> limp_at_{};
};

}  // namespace crease::world
