#include "plugins/sim_world/world_devices.h"

#include <cmath>

namespace crease::world {

WorldDevices::WorldDevices(World& world, drivers::sim::SimRobotConfig cfg) : world_(world) {
  cfg.hand_external_positions = true;
  for (int s = 0; s < robot::kSides; ++s) {
    const auto& q = world.arm_angles(static_cast<Side>(s));
    for (int j = 0; j < robot::kArmJoints; ++j) cfg.arm_initial_rad[s][j] = static_cast<float>(q[j]);
  }
  robot_ = std::make_unique<drivers::sim::SimRobot>(cfg);
  report_hand_angles_rt();
}

void WorldDevices::report_hand_angles_rt() noexcept {
  for (int s = 0; s < robot::kSides; ++s) {
    const auto& q = world_.hand_angles(static_cast<Side>(s));
    float rad[robot::kHandJoints];
    for (int j = 0; j < robot::kHandJoints; ++j) rad[j] = static_cast<float>(q[j]);
    robot_->hand(s).set_joint_positions(rad);
  }
}

void WorldDevices::step_rt() noexcept {
  device_ns_ = kEpochNs + static_cast<std::int64_t>(std::llround(world_.time_s() * 1e9));
  robot_->step_rt(device_ns_);
  for (int s = 0; s < robot::kSides; ++s) {
    const Side side = static_cast<Side>(s);
    const drivers::sim::SimHand& hand = robot_->hand(s);
    World::HandJoints target{}, stiffness{};
    if (hand.limp()) {
      if (!limp_[s]) limp_at_[s] = world_.hand_angles(side);
      target = limp_at_[s];  // stiffness 0: limp where it went limp
    } else {
      for (int j = 0; j < robot::kHandJoints; ++j) {
        target[j] = hand.commanded_target(j);
        stiffness[j] = hand.commanded_stiffness(j);
      }
    }
    limp_[s] = hand.limp();
    world_.command_hand_rt(side, target, stiffness);
    World::ArmJoints q{};
    for (int j = 0; j < robot::kArmJoints; ++j) q[j] = robot_->arm(s).position(j);
    world_.command_arm_rt(side, q);
  }
  world_.step_rt();
  report_hand_angles_rt();
}

}  // namespace crease::world
