// The checks a goal must pass when it arrives, before anything about the arm is looked at: its
// shape (kind, frame, stop condition, point count, tool), finite numbers, unit quaternions,
// limits within arm_motion's parameters, and (once in the world frame) the workspace box.
// RT: pure functions on plain data.
#pragma once

#include <array>

#include "core/port_types/arm_goal.h"
#include "plugins/arm_motion/cartesian_path.h"

namespace crease::arm_motion {

// The most a goal may ask (arm_motion's parameters), mm, rad, s.
struct GoalLimits {
  double max_speed_mm_s = 250;
  double max_accel_mm_s2 = 2000;
  double max_angular_speed_rad_s = 1.5;
  double max_angular_accel_rad_s2 = 12;
  double max_stop_accel_mm_s2 = 5000;
};

// The workspace the tool frame's points must lie in (world, mm): an axis-aligned box.
struct Workspace {
  std::array<double, 3> min_mm = {-700, -800, -10};
  std::array<double, 3> max_mm = {700, 600, 900};
  [[nodiscard]] bool contains(const double* p_mm) const noexcept {
    for (int i = 0; i < 3; ++i)
      if (!(p_mm[i] >= min_mm[i] && p_mm[i] <= max_mm[i])) return false;
    return true;
  }
};

// ArmMotionReason::none when the goal's own content is acceptable, else the first reason found
// in this order: bad_points (kind, frame, stop_on, point_count; a joints goal: one point, no stop
// condition, not in the measured frame), unknown_tool, non_finite,
// bad_orientation, bad_limits. A stop goal is checked for its kind only.
[[nodiscard]] ArmMotionReason check_goal(const ArmGoal& goal, const GoalLimits& limits) noexcept;

// A lift: the safe direction, away from the sheet and the table (world +z). True when every
// segment of PATH (its start, the tool's commanded pose, included) ends no lower than it starts
// and moves sideways at most as far as it rises, plus kLiftSlackMm (within 45 deg of straight
// up: the start is the commanded pose, a measured-frame goal's points are off the measured
// one), the whole path rises more than kLiftSlackMm, and the orientation turns by at most
// kLiftMaxTurnRad in all (a turn about the tool frame could lower the rest of the hand). Such a
// motion is the one arm_motion accepts and runs while the hand's controller retreats.
inline constexpr double kLiftSlackMm = 1.0;
inline constexpr double kLiftMaxTurnRad = 0.05;
[[nodiscard]] bool path_is_lift(const CartesianPath& path) noexcept;

}  // namespace crease::arm_motion
