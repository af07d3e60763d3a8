#include "plugins/arm_motion/cartesian_path.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace crease::arm_motion {

namespace {
constexpr double kTiny = 1e-9;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Unit quaternion slerp (x y z w), shortest way round.
void slerp(const double* a, const double* b, double t, double* out) noexcept {
  double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  double bb[4] = {b[0], b[1], b[2], b[3]};
  if (d < 0) {
    d = -d;
    for (double& x : bb) x = -x;
  }
  double wa, wb;
  if (d > 0.9999995) {  // nearly equal: linear, then normalised
    wa = 1 - t;
    wb = t;
  } else {
    const double th = std::acos(d), s = std::sin(th);
    wa = std::sin((1 - t) * th) / s;
    wb = std::sin(t * th) / s;
  }
  double n = 0;
  for (int i = 0; i < 4; ++i) {
    out[i] = wa * a[i] + wb * bb[i];
    n += out[i] * out[i];
  }
  n = std::sqrt(n);
  for (int i = 0; i < 4; ++i) out[i] /= n;
}
}  // namespace

KDL::Frame to_frame(const PathPose& p) noexcept {
  return KDL::Frame(KDL::Rotation::Quaternion(p.quat[0], p.quat[1], p.quat[2], p.quat[3]),
                    KDL::Vector(p.p_m[0], p.p_m[1], p.p_m[2]));
}

PathPose to_pose(const KDL::Frame& f) noexcept {
  PathPose p;
  for (int i = 0; i < 3; ++i) p.p_m[i] = f.p(i);
  f.M.GetQuaternion(p.quat[0], p.quat[1], p.quat[2], p.quat[3]);
  return p;
}

void set_path_limits(CartesianPath& path, const PathLimits& l) noexcept {
  for (int k = 0; k < path.segments(); ++k) {
    const PathPose &a = path.pose[k], &b = path.pose[k + 1];
    double len2 = 0;
    for (int i = 0; i < 3; ++i) len2 += (b.p_m[i] - a.p_m[i]) * (b.p_m[i] - a.p_m[i]);
    const double d = std::abs(a.quat[0] * b.quat[0] + a.quat[1] * b.quat[1] + a.quat[2] * b.quat[2] + a.quat[3] * b.quat[3]);
    path.length_m[k] = std::sqrt(len2);
    path.angle_rad[k] = 2.0 * std::acos(std::min(1.0, d));
    double sd = kInf, sdd = kInf, stop = kInf;
    if (path.length_m[k] > kTiny) {
      sd = std::min(sd, l.speed_m_s / path.length_m[k]);
      sdd = std::min(sdd, l.accel_m_s2 / path.length_m[k]);
      stop = std::min(stop, l.stop_accel_m_s2 / path.length_m[k]);
    }
    if (path.angle_rad[k] > kTiny) {
      sd = std::min(sd, l.angular_speed_rad_s / path.angle_rad[k]);
      sdd = std::min(sdd, l.angular_accel_rad_s2 / path.angle_rad[k]);
      // The stop brakes rotation no harder than the stop-to-travel ratio of the linear limits.
      stop = std::min(stop, l.angular_accel_rad_s2 * (l.stop_accel_m_s2 / l.accel_m_s2) / path.angle_rad[k]);
    }
    path.sd_max[k] = sd;
    // The discrete braking curve's last cycle lands with up to 9/8 of the planned
    // deceleration (braking_speed): planning with 8/9 keeps every cycle within the limit.
    path.sdd_max[k] = sdd * (8.0 / 9.0);
    path.sdd_stop[k] = stop;
  }
}

KDL::Frame pose_at(const CartesianPath& path, int segment, double sigma) noexcept {
  const PathPose &a = path.pose[segment], &b = path.pose[segment + 1];
  PathPose p;
  for (int i = 0; i < 3; ++i) p.p_m[i] = a.p_m[i] + sigma * (b.p_m[i] - a.p_m[i]);
  slerp(a.quat, b.quat, sigma, p.quat);
  return to_frame(p);
}

double braking_speed(double d, double sdd, double dt) noexcept {
  // Braking from k * sdd * dt in steps of sdd * dt covers sdd dt^2 k (k + 1) / 2, this cycle's
  // step included: the largest k with that within d.
  if (d <= 0) return 0;
  const double u = sdd * dt * dt;
  const double k = 0.5 * (std::sqrt(1.0 + 8.0 * d / u) - 1.0);
  return k * sdd * dt;
}

double step_profile(const CartesianPath& path, PathProfile& pr, double dt) noexcept {
  if (pr.done || pr.segment >= path.segments()) {
    pr.done = 1;
    pr.sigma_dot = 0;
    return 0;
  }
  const int k = pr.segment;
  const double remaining = 1.0 - pr.sigma;
  double v;
  if (pr.stopping) {
    v = std::max(0.0, pr.sigma_dot - path.sdd_stop[k] * dt);
  } else if (!std::isfinite(path.sd_max[k])) {
    v = remaining / dt;  // nothing to move: passed in one cycle
  } else {
    const double a = path.sdd_max[k];
    v = std::min({pr.sigma_dot + a * dt, path.sd_max[k], braking_speed(remaining, a, dt)});
    v = std::max({v, pr.sigma_dot - a * dt, 0.0});
  }
  if (pr.sigma + v * dt >= 1.0 - 1e-12) {
    pr.sigma = 1.0;
    pr.sigma_dot = 0;
    if (pr.stopping || k + 1 >= path.segments()) {
      pr.done = 1;
    } else {
      pr.segment = k + 1;
      pr.sigma = 0;
    }
    return 0;
  }
  pr.sigma += v * dt;
  pr.sigma_dot = v;
  if (pr.stopping && v == 0) pr.done = 1;
  return v * path.length_m[k];
}

double path_progress(const CartesianPath& path, const PathProfile& pr) noexcept {
  if (path.segments() <= 0) return 1.0;
  if (pr.done && !pr.stopping) return 1.0;
  return std::min(1.0, (pr.segment + pr.sigma) / path.segments());
}

double distance_to_go_m(const CartesianPath& path, const PathProfile& pr) noexcept {
  if (path.segments() <= 0 || (pr.done && !pr.stopping)) return 0;
  double d = (1.0 - pr.sigma) * path.length_m[pr.segment];
  for (int k = pr.segment + 1; k < path.segments(); ++k) d += path.length_m[k];
  return d;
}

}  // namespace crease::arm_motion
