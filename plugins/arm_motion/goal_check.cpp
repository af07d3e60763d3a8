#include "plugins/arm_motion/goal_check.h"

#include <algorithm>
#include <cmath>

#include "plugins/robot_model/robot_layout.h"

namespace crease::arm_motion {

ArmMotionReason check_goal(const ArmGoal& g, const GoalLimits& l) noexcept {
  if (g.kind == ArmGoal::stop) return ArmMotionReason::none;
  if ((g.kind != ArmGoal::move && g.kind != ArmGoal::retreat) ||
      (g.frame != ArmGoal::world && g.frame != ArmGoal::sheet && g.frame != ArmGoal::measured) ||
      (g.stop_on != ArmGoal::stop_none && g.stop_on != ArmGoal::contact_onset) ||
      g.point_count == 0 || g.point_count > ArmGoal::kMaxPoints ||
      (g.stop_on != ArmGoal::stop_none && (g.stop_fingers & 0x1f) == 0)) {
    return ArmMotionReason::bad_points;
  }
  if (g.interpolation != ArmGoal::cartesian &&
      (g.interpolation != ArmGoal::joints || g.point_count != 1 || g.stop_on != ArmGoal::stop_none ||
       g.frame == ArmGoal::measured))
    return ArmMotionReason::bad_points;
  if (g.tool >= robot::kToolFrames) return ArmMotionReason::unknown_tool;
  const float lim[] = {g.speed_mm_s, g.accel_mm_s2, g.angular_speed_rad_s, g.angular_accel_rad_s2, g.stop_accel_mm_s2};
  for (float x : lim)
    if (!std::isfinite(x)) return ArmMotionReason::non_finite;
  for (int k = 0; k < g.point_count; ++k) {
    for (double x : g.position_mm[k])
      if (!std::isfinite(x)) return ArmMotionReason::non_finite;
    for (double x : g.orientation[k])
      if (!std::isfinite(x)) return ArmMotionReason::non_finite;
  }
  for (int k = 0; k < g.point_count; ++k) {
    const double* q = g.orientation[k];
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (std::abs(n - 1.0) > 1e-3) return ArmMotionReason::bad_orientation;
  }
  const auto within = [](double v, double hi) { return v > 0 && v <= hi; };
  if (!within(g.speed_mm_s, l.max_speed_mm_s) || !within(g.accel_mm_s2, l.max_accel_mm_s2) ||
      !within(g.angular_speed_rad_s, l.max_angular_speed_rad_s) ||
      !within(g.angular_accel_rad_s2, l.max_angular_accel_rad_s2) ||
      !within(g.stop_accel_mm_s2, l.max_stop_accel_mm_s2) || g.stop_accel_mm_s2 < g.accel_mm_s2) {
    return ArmMotionReason::bad_limits;
  }
  return ArmMotionReason::none;
}

bool path_is_lift(const CartesianPath& path) noexcept {
  if (path.count < 2 || path.count > CartesianPath::kMaxPoints) return false;
  double turn = 0;
  for (int k = 0; k + 1 < path.count; ++k) {
    const PathPose& a = path.pose[k];
    const PathPose& b = path.pose[k + 1];
    const double rise_mm = 1000.0 * (b.p_m[2] - a.p_m[2]);
    const double side_mm = 1000.0 * std::hypot(b.p_m[0] - a.p_m[0], b.p_m[1] - a.p_m[1]);
    if (!(rise_mm >= 0.0 && side_mm <= rise_mm + kLiftSlackMm)) return false;  // NaN: not a lift
    double dot = 0;
    for (int c = 0; c < 4; ++c) dot += a.quat[c] * b.quat[c];
    turn += 2.0 * std::acos(std::min(1.0, std::abs(dot)));
  }
  const double total_mm = 1000.0 * (path.pose[path.count - 1].p_m[2] - path.pose[0].p_m[2]);
  return total_mm > kLiftSlackMm && turn <= kLiftMaxTurnRad;
}

}  // namespace crease::arm_motion
