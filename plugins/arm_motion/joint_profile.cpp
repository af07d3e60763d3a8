#include "plugins/arm_motion/joint_profile.h"

#include <algorithm>
#include <cmath>

namespace crease::arm_motion {
namespace {

constexpr double kPeakVel = 1.875;   // max of ds/dtau
constexpr double kPeakAcc = 5.7735;  // max of |d2s/dtau2| (10 / sqrt(3))

double scaling(double tau) noexcept { return tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau)); }

}  // namespace

JointProfile joint_profile(const double (&from)[robot::kArmJoints], const double (&to)[robot::kArmJoints],
                           const double (&vmax)[robot::kArmJoints], double amax) noexcept {
  JointProfile p;
  double T = 0;
  for (int j = 0; j < robot::kArmJoints; ++j) {
    p.from[j] = from[j];
    p.to[j] = to[j];
    const double d = std::abs(to[j] - from[j]);
    T = std::max({T, kPeakVel * d / vmax[j], std::sqrt(kPeakAcc * d / amax)});
  }
  p.duration_s = T;
  p.done = T <= 0 ? 1 : 0;
  return p;
}

void step_joint_profile(JointProfile& p, double dt_s, double amax, double (&q)[robot::kArmJoints],
                        double (&v)[robot::kArmJoints]) noexcept {
  if (p.stopping) {
    bool moving = false;
    for (int j = 0; j < robot::kArmJoints; ++j) {
      const double dv = std::min(std::abs(p.v_stop[j]), amax * dt_s);
      p.v_stop[j] -= std::copysign(dv, p.v_stop[j]);
      q[j] += p.v_stop[j] * dt_s;
      v[j] = p.v_stop[j];
      moving = moving || p.v_stop[j] != 0.0;
    }
    p.done = moving ? 0 : 1;
    return;
  }
  p.t_s = std::min(p.t_s + dt_s, p.duration_s);
  const double tau = p.duration_s > 0 ? p.t_s / p.duration_s : 1.0;
  const double s = scaling(tau);
  for (int j = 0; j < robot::kArmJoints; ++j) {
    const double next = p.from[j] + s * (p.to[j] - p.from[j]);
    v[j] = dt_s > 0 ? (next - q[j]) / dt_s : 0.0;  // the step over the cycle, as a path's command
    q[j] = next;
  }
  p.done = p.t_s >= p.duration_s ? 1 : 0;
}

void stop_joint_profile(JointProfile& p, const double (&v)[robot::kArmJoints]) noexcept {
  p.stopping = 1;
  for (int j = 0; j < robot::kArmJoints; ++j) p.v_stop[j] = v[j];
}

double joint_profile_progress(const JointProfile& p) noexcept {
  if (p.duration_s <= 0) return 1.0;
  return scaling(std::clamp(p.t_s / p.duration_s, 0.0, 1.0));
}

}  // namespace crease::arm_motion
