// Test support for arm_motion: the shipped robot, an arm that follows its command exactly (the
// ArmState a perfect drive would report), goals, and the tool frame's pose from the commanded
// angles through robot_model's own forward kinematics (not the controller's belief).
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "core/port_types/arm.h"
#include "core/port_types/arm_goal.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/hand_control.h"
#include "plugins/arm_motion/arm_motion.h"
#include "plugins/robot_model/robot_model.h"

namespace rig {

using namespace crease;
using namespace crease::arm_motion;
using robot::Side;
using robot::ToolFrame;
using Joints = std::array<double, robot::kArmJoints>;
using Hand = std::array<double, robot::kHandJoints>;

inline robot::RobotModel& model() {
  static robot::RobotModel m = robot::RobotModel::load(std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml");
  return m;
}

// The right palm flat 150 mm above the table, fingers forward (arm_motion's default rest posture).
inline Joints start_posture() { return {-0.535, -0.993, -0.427, 1.890, 0.819, 1.125, 2.230}; }

// The controller's defaults with the rest posture at the start posture.
inline MotionParams params() {
  MotionParams p;
  p.ik.rest_rad = start_posture();
  return p;
}

constexpr std::int64_t kPeriod = 1'000'000;  // 1 kHz

// One arm driven by a controller: the arm follows the command exactly, one cycle late (what the
// drivers report in the next cycle's update), the hand stays at HAND.
struct Rig {
  explicit Rig(MotionParams p = params(), Side s = Side::right, Joints q0 = start_posture())
      : side(s), motion(std::make_unique<ArmMotion>(model(), s, p)), q_arm(q0) {
    contact.armed = 1;
    contact.healthy = 1;
  }

  // One control cycle: the arm's state now, goals, the controller's step; the arm takes the
  // command (for the next cycle). Returns whether a command was written.
  bool cycle(const ArmGoal* goal = nullptr) {
    now += kPeriod;
    arm.timestamp_ns = now;
    arm.valid = 0x7f;
    arm.fresh = 1;
    arm.drive_state = drive_state;
    arm.health = health;
    for (int j = 0; j < robot::kArmJoints; ++j) arm.position_rad[j] = static_cast<float>(q_arm[j]);
    if (arm_fresh) arm_stamp = now;
    arm.timestamp_ns = arm_stamp;
    hand_state.timestamp_ns = now;
    hand_state.health = DeviceHealth::ok;
    for (int j = 0; j < robot::kHandJoints; ++j) hand_state.position_rad[j] = static_cast<float>(hand[j]);
    if (contact_fresh) contact.timestamp_ns = now;
    CycleInputs in;
    in.now_ns = now;
    in.dt_s = 1e-3;
    in.arm = &arm;
    in.hand = hand_present ? &hand_state : nullptr;
    in.contact = &contact;
    if (hand_control_fresh) hand_control.timestamp_ns = now;
    in.hand_control = hand_control_present ? &hand_control : nullptr;
    if (goal != nullptr) motion->on_goal(*goal, in, sheet_frame);
    const bool wrote = motion->step(in);
    if (wrote) {
      last = motion->command();
      if (follow)
        for (int j = 0; j < robot::kArmJoints; ++j) q_arm[j] = last.position_rad[j];
    }
    return wrote;
  }
  // Cycles until the motion is no longer checking, running or stopping (at most N).
  int run_to_end(int n = 20000) {
    int i = 0;
    for (; i < n && active(); ++i) cycle();
    return i;
  }
  [[nodiscard]] bool active() const {
    const auto s = motion->status().state;
    return s == ArmMotionStatus::checking || s == ArmMotionStatus::running || s == ArmMotionStatus::stopping;
  }

  // The tool frame's world pose (mm) at the commanded angles, from robot_model's FK.
  KDL::Frame tool_pose(ToolFrame f) {
    Joints q{};
    for (int j = 0; j < robot::kArmJoints; ++j) q[j] = last.position_rad[j];
    KDL::Frame out;
    REQUIRE(model().tool_pose_m(side, f, q, hand, out));
    return out;
  }
  KDL::Frame tool_pose_at(ToolFrame f, const Joints& q) {
    KDL::Frame out;
    REQUIRE(model().tool_pose_m(side, f, q, hand, out));
    return out;
  }

  Side side;
  std::unique_ptr<ArmMotion> motion;
  Joints q_arm;
  Hand hand{};
  ArmState arm;
  HandState hand_state;
  ContactState contact;
  HandControlStatus hand_control;  // the hand's force_controller: holding, no inhibit
  ArmCommand last;
  std::int64_t now = 1'000'000'000;
  std::int64_t arm_stamp = 0;
  std::uint8_t drive_state = 4;
  DeviceHealth health = DeviceHealth::ok;
  bool arm_fresh = true, contact_fresh = true, follow = true, hand_present = true;
  bool hand_control_present = true, hand_control_fresh = true;
  const KDL::Frame* sheet_frame = nullptr;
};

// A move goal of TOOL to POSE (world, metres), with limits.
inline ArmGoal goal_to(ToolFrame tool, const KDL::Frame& pose, std::uint32_t id = 1, double speed_mm_s = 100,
                       double accel_mm_s2 = 1000) {
  ArmGoal g;
  g.id = id;
  g.kind = ArmGoal::move;
  g.tool = static_cast<std::uint8_t>(tool);
  g.frame = ArmGoal::world;
  g.point_count = 1;
  g.speed_mm_s = static_cast<float>(speed_mm_s);
  g.accel_mm_s2 = static_cast<float>(accel_mm_s2);
  g.angular_speed_rad_s = 1.0f;
  g.angular_accel_rad_s2 = 10.0f;
  g.stop_accel_mm_s2 = static_cast<float>(2 * accel_mm_s2);
  for (int i = 0; i < 3; ++i) g.position_mm[0][i] = 1000.0 * pose.p(i);
  pose.M.GetQuaternion(g.orientation[0][0], g.orientation[0][1], g.orientation[0][2], g.orientation[0][3]);
  return g;
}

// Appends a point (a via point before the last becomes the target).
inline void add_point(ArmGoal& g, const KDL::Frame& pose) {
  const int k = g.point_count++;
  for (int i = 0; i < 3; ++i) g.position_mm[k][i] = 1000.0 * pose.p(i);
  pose.M.GetQuaternion(g.orientation[k][0], g.orientation[k][1], g.orientation[k][2], g.orientation[k][3]);
}

// The command's joint angles in double (the controller's own q_cmd; the port carries floats).
inline Joints q_cmd(const Rig& r) {
  Joints q{};
  for (int j = 0; j < robot::kArmJoints; ++j) q[j] = r.motion->state().q_cmd[j];
  return q;
}

// Exact at small differences (KDL's Norm and diff read values under 1e-6 as 0).
inline double norm(const KDL::Vector& v) { return std::sqrt(KDL::dot(v, v)); }
inline double mm(const KDL::Vector& v) { return 1000.0 * norm(v); }
// The angle between two rotations: |A - B|_F = 2 sqrt(2) sin(theta / 2).
inline double rot_angle(const KDL::Rotation& a, const KDL::Rotation& b) {
  double f = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f += (a(i, j) - b(i, j)) * (a(i, j) - b(i, j));
  return 2.0 * std::asin(std::min(1.0, std::sqrt(f) / (2.0 * std::sqrt(2.0))));
}

}  // namespace rig
