// A tool frame's Cartesian path through up to ArmGoal::kMaxPoints poses and its
// jerk-limited (or, with no jerk limit, acceleration-limited) timing, stepped once per control
// cycle.
//
// Geometry: the start pose, then each point; segment k goes from point k to point k+1, its
// position on the straight line, its orientation by slerp, both as the same parameter
// sigma in [0, 1]. Every segment starts and ends at rest (a via point is passed at zero speed:
// no blending), so the path is exactly the polyline and no corner is cut.
// Limits (per segment, in sigma): sigma_dot <= min(v / L, w / theta), sigma_ddot <= min(a / L,
// alpha / theta), sigma_dddot <= min(j / L, j_w / theta), so the tool's linear and angular
// speed, acceleration and jerk stay within the limits.
// Jerk-limited (finite jerk limits): each segment's timing is the rest-to-rest S-curve of those
// limits (jerk +j, 0, -j up to the cruise speed, cruise, and the mirror image down to rest; the
// acceleration or the cruise phase shrinks to nothing on a short segment), computed in closed
// form when the limits are set and sampled at the cycle's time, so the sampled poses' finite
// differences stay within the continuous limits and the last sample lands on sigma = 1. A stop
// takes the state (sigma, sigma_dot, sigma_ddot) of its first cycle and brakes from it in closed
// form: jerk -j_stop down to at most the stop deceleration, hold, +j_stop back to rest (so from
// a cruise the stop's first cycle is already slower; from an acceleration phase the speed may
// still rise for the cycles the acceleration takes to turn).
// Acceleration-limited (jerk limits 0): computed online: accelerate, cruise, and brake on the
// exact discrete-time braking curve, planned at 8/9 of the acceleration limit (its last cycle
// lands on sigma = 1 with up to 9/8 of the planned deceleration); a stop brakes at the stop
// deceleration from wherever it is.
// Plain data throughout (carried across a hot-swap byte for byte). RT: nothing allocates.
// Metres, radians, seconds.
#pragma once

#include <kdl/frames.hpp>

#include <cstdint>

#include "core/port_types/arm_goal.h"

namespace crease::arm_motion {

struct PathPose {
  double p_m[3] = {};
  double quat[4] = {0, 0, 0, 1};  // x y z w
};

struct CartesianPath {
  static constexpr int kMaxPoints = ArmGoal::kMaxPoints + 1;  // the start and the goal's points
  int count = 0;                      // poses, the start included (>= 2 for a motion)
  PathPose pose[kMaxPoints];
  double length_m[kMaxPoints] = {};   // per segment
  double angle_rad[kMaxPoints] = {};
  double sd_max[kMaxPoints] = {};     // 1/s
  double sdd_max[kMaxPoints] = {};    // 1/s^2
  double sdd_stop[kMaxPoints] = {};   // 1/s^2, the stop deceleration
  // Jerk-limited timing (0 jerk: acceleration-limited). Per segment: the jerk limits (1/s^3)
  // and the S-curve: jerk ramp time, acceleration time (to the cruise speed), cruise time (s),
  // its peak sigma_dot.
  double sddd_max[kMaxPoints] = {};
  double sddd_stop[kMaxPoints] = {};
  double sdd_limit[kMaxPoints] = {};  // the acceleration limit itself (sdd_max is 8/9 of it)
  double t_jerk[kMaxPoints] = {}, t_accel[kMaxPoints] = {}, t_cruise[kMaxPoints] = {}, sd_peak[kMaxPoints] = {};
  [[nodiscard]] int segments() const noexcept { return count - 1; }
};

struct PathLimits {
  double speed_m_s = 0, accel_m_s2 = 0, angular_speed_rad_s = 0, angular_accel_rad_s2 = 0, stop_accel_m_s2 = 0;
  // 0: no jerk limit (acceleration-limited). All three finite and > 0, or all 0.
  double jerk_m_s3 = 0, angular_jerk_rad_s3 = 0, stop_jerk_m_s3 = 0;
};

// The timing state along a path.
struct PathProfile {
  int segment = 0;
  double sigma = 0;      // along the segment, 0..1
  double sigma_dot = 0;  // 1/s
  double sigma_ddot = 0;  // 1/s^2 (jerk-limited timing; 0 otherwise)
  double t = 0;           // s into the segment's S-curve
  // A jerk-limited stop: its start (sigma, sigma_dot, sigma_ddot), its phases (s: jerk -j, hold,
  // +j), its jerk (1/s^3) and the time since it began.
  double stop_s0 = 0, stop_v0 = 0, stop_a0 = 0, stop_t1 = 0, stop_t2 = 0, stop_t3 = 0, stop_j = 0, stop_t = 0;
  std::uint8_t stopping = 0;
  std::uint8_t stop_planned = 0;
  std::uint8_t done = 0;  // the end of the path reached, or a stop came to rest
};

[[nodiscard]] KDL::Frame to_frame(const PathPose& p) noexcept;
[[nodiscard]] PathPose to_pose(const KDL::Frame& f) noexcept;

// RT. Fills lengths, angles and each segment's sigma limits. A segment with neither length nor
// angle (under 1 nm and 1 nrad) has infinite limits: the profile passes it in one cycle.
void set_path_limits(CartesianPath& path, const PathLimits& limits) noexcept;

// RT. The pose at SIGMA along SEGMENT.
[[nodiscard]] KDL::Frame pose_at(const CartesianPath& path, int segment, double sigma) noexcept;

// RT. True when PATH's timing is jerk-limited.
[[nodiscard]] bool jerk_limited(const CartesianPath& path) noexcept;

// RT. One cycle of DT seconds. Returns the tool's path speed after it (m/s along the segment).
double step_profile(const CartesianPath& path, PathProfile& profile, double dt) noexcept;

// RT. The fastest sigma_dot from which braking at SDD (1/s^2) in steps of DT stops within D.
[[nodiscard]] double braking_speed(double d, double sdd, double dt) noexcept;

// RT. Along the whole path: progress 0..1 (segments counted equally) and metres still to go.
[[nodiscard]] double path_progress(const CartesianPath& path, const PathProfile& profile) noexcept;
[[nodiscard]] double distance_to_go_m(const CartesianPath& path, const PathProfile& profile) noexcept;

}  // namespace crease::arm_motion
