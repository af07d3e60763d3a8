// A joint-space move of the 7 arm joints (ArmGoal::joints): every joint from FROM to TO on one
// quintic time scaling s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, tau = t / T (zero velocity and
// acceleration at both ends), T the shortest duration in which no joint exceeds its speed
// (peak 1.875 |dq| / T) or acceleration (peak 5.774 |dq| / T^2) limit. A stop leaves the profile
// and decelerates each joint at its acceleration limit to rest. Radians, seconds. Plain data
// (carried across a hot-swap in MotionState); RT: no allocation.
#pragma once

#include "plugins/robot_model/robot_layout.h"

namespace crease::arm_motion {

struct JointProfile {
  static constexpr int kJoints = robot::kArmJoints;
  double from[kJoints] = {};
  double to[kJoints] = {};
  double t_s = 0;
  double duration_s = 0;
  double v_stop[kJoints] = {};  // while stopping: the joints' velocities
  unsigned char stopping = 0;
  unsigned char done = 0;
};

// RT. A profile from FROM to TO under VMAX (rad/s) and AMAX (rad/s^2) per joint (each > 0).
[[nodiscard]] JointProfile joint_profile(const double (&from)[robot::kArmJoints], const double (&to)[robot::kArmJoints],
                                         const double (&vmax)[robot::kArmJoints], double amax) noexcept;

// RT. Advances P by DT_S; Q (in: the last command, out: the next) and V (out: the step over
// the cycle, the velocity a path's command carries too).
void step_joint_profile(JointProfile& p, double dt_s, double amax, double (&q)[robot::kArmJoints],
                        double (&v)[robot::kArmJoints]) noexcept;

// RT. From now on P decelerates to rest from V (the last velocities) at AMAX.
void stop_joint_profile(JointProfile& p, const double (&v)[robot::kArmJoints]) noexcept;

// The fraction of the way done (0..1).
[[nodiscard]] double joint_profile_progress(const JointProfile& p) noexcept;

}  // namespace crease::arm_motion
