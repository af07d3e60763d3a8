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
// Integrates piecewise-constant jerk phases (durations DUR, jerks JERK) from (s, v, a) for T
// seconds (at most their total).
void integrate(const double* dur, const double* jerk, int n, double t, double& s, double& v, double& a) noexcept {
  for (int i = 0; i < n && t > 0; ++i) {
    const double h = std::min(t, std::max(0.0, dur[i])), j = jerk[i];
    s += v * h + a * h * h / 2 + j * h * h * h / 6;
    v += a * h + j * h * h / 2;
    a += j * h;
    t -= h;
  }
}

// The rest-to-rest S-curve over sigma 0..1 with SD, SDD, SDDD: its jerk ramp, acceleration and
// cruise times and its peak speed.
void s_curve(double sd, double sdd, double sddd, double& tj, double& ta, double& tv, double& peak) noexcept {
  double v = sd;
  tj = std::min(sdd / sddd, std::sqrt(v / sddd));
  ta = v / (sddd * tj) + tj;  // to v: jerk up, hold the acceleration, jerk down
  if (v * ta > 1.0) {         // too short to cruise at sd: the fastest peak that fits
    const double with_a = 0.5 * sdd * (-sdd / sddd + std::sqrt(sdd * sdd / (sddd * sddd) + 4.0 / sdd));
    if (with_a >= sdd * sdd / sddd) {  // the acceleration limit still reached
      v = with_a;
      tj = sdd / sddd;
      ta = v / sdd + tj;
    } else {  // not even that: jerk up and straight down
      v = std::cbrt(sddd / 4.0);
      tj = std::sqrt(v / sddd);
      ta = 2 * tj;
    }
  }
  tv = std::max(0.0, (1.0 - v * ta) / v);
  peak = v;
}

// Sigma, its speed and acceleration T seconds into segment K's S-curve.
void s_curve_at(const CartesianPath& path, int k, double t, double& s, double& v, double& a) noexcept {
  const double tj = path.t_jerk[k], ta = path.t_accel[k], tv = path.t_cruise[k], j = path.sddd_max[k];
  const double dur[7] = {tj, ta - 2 * tj, tj, tv, tj, ta - 2 * tj, tj};
  const double jerk[7] = {j, 0, -j, 0, -j, 0, j};
  s = v = a = 0;
  integrate(dur, jerk, 7, t, s, v, a);
}

// Plans a jerk-limited stop from the profile's state: jerk -j down to a1 >= -A, hold, +j to
// rest, reaching sigma_dot = 0 with sigma_ddot = 0.
void plan_stop(const CartesianPath& path, PathProfile& pr) noexcept {
  const int k = pr.segment;
  const double J = path.sddd_stop[k], A = path.sdd_stop[k], v0 = std::max(0.0, pr.sigma_dot), a0 = pr.sigma_ddot;
  double a1 = -std::sqrt(std::max(0.0, J * v0 + 0.5 * a0 * a0)), t2 = 0;
  if (a1 < -A) {
    a1 = -A;
    t2 = std::max(0.0, (v0 + a0 * a0 / (2 * J) - A * A / J) / A);
  }
  double t1 = (a0 - a1) / J;
  if (t1 < 0) {  // already braking harder than needed: hold it, then ease off
    a1 = a0;
    t1 = 0;
    t2 = std::max(0.0, (v0 - a0 * a0 / (2 * J)) / -a0);
  }
  pr.stop_s0 = pr.sigma;
  pr.stop_v0 = v0;
  pr.stop_a0 = a0;
  pr.stop_t1 = t1;
  pr.stop_t2 = t2;
  pr.stop_t3 = -a1 / J;
  pr.stop_j = J;
  pr.stop_t = 0;
  pr.stop_planned = 1;
}

double step_jerk_limited(const CartesianPath& path, PathProfile& pr, double dt) noexcept {
  const int k = pr.segment;
  if (pr.stopping) {
    if (!pr.stop_planned) plan_stop(path, pr);
    pr.stop_t += dt;
    const double total = pr.stop_t1 + pr.stop_t2 + pr.stop_t3;
    const double dur[3] = {pr.stop_t1, pr.stop_t2, pr.stop_t3}, jerk[3] = {-pr.stop_j, 0, pr.stop_j};
    double s = pr.stop_s0, v = pr.stop_v0, a = pr.stop_a0;
    integrate(dur, jerk, 3, std::min(pr.stop_t, total), s, v, a);
    pr.sigma = std::min(1.0, s);
    pr.sigma_dot = std::max(0.0, v);
    pr.sigma_ddot = a;
    if (pr.stop_t >= total || pr.sigma >= 1.0) {
      pr.sigma_dot = pr.sigma_ddot = 0;
      pr.done = 1;
    }
    return pr.sigma_dot * path.length_m[k];
  }
  pr.t += dt;
  const double total = 2 * path.t_accel[k] + path.t_cruise[k];
  if (pr.t >= total) {  // the segment's end, exactly
    pr.sigma = 1.0;
    pr.sigma_dot = pr.sigma_ddot = 0;
    if (k + 1 >= path.segments()) {
      pr.done = 1;
    } else {
      pr.segment = k + 1;
      pr.sigma = 0;
      pr.t = 0;
    }
    return 0;
  }
  double sg = 0, v = 0, a = 0;
  s_curve_at(path, k, pr.t, sg, v, a);
  pr.sigma = std::clamp(sg, 0.0, 1.0);
  pr.sigma_dot = v;
  pr.sigma_ddot = a;
  return v * path.length_m[k];
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
    double sd = kInf, sdd = kInf, stop = kInf, jerk = kInf, stop_jerk = kInf;
    const bool jerked = l.jerk_m_s3 > 0;
    if (path.length_m[k] > kTiny) {
      sd = std::min(sd, l.speed_m_s / path.length_m[k]);
      sdd = std::min(sdd, l.accel_m_s2 / path.length_m[k]);
      stop = std::min(stop, l.stop_accel_m_s2 / path.length_m[k]);
      if (jerked) {
        jerk = std::min(jerk, l.jerk_m_s3 / path.length_m[k]);
        stop_jerk = std::min(stop_jerk, l.stop_jerk_m_s3 / path.length_m[k]);
      }
    }
    if (path.angle_rad[k] > kTiny) {
      sd = std::min(sd, l.angular_speed_rad_s / path.angle_rad[k]);
      sdd = std::min(sdd, l.angular_accel_rad_s2 / path.angle_rad[k]);
      // The stop brakes rotation no harder than the stop-to-travel ratio of the linear limits.
      stop = std::min(stop, l.angular_accel_rad_s2 * (l.stop_accel_m_s2 / l.accel_m_s2) / path.angle_rad[k]);
      if (jerked) {
        jerk = std::min(jerk, l.angular_jerk_rad_s3 / path.angle_rad[k]);
        stop_jerk = std::min(stop_jerk, l.angular_jerk_rad_s3 * (l.stop_jerk_m_s3 / l.jerk_m_s3) / path.angle_rad[k]);
      }
    }
    path.sd_max[k] = sd;
    path.sdd_limit[k] = sdd;
    path.sddd_max[k] = jerked ? jerk : 0.0;
    path.sddd_stop[k] = jerked ? stop_jerk : 0.0;
    path.t_jerk[k] = path.t_accel[k] = path.t_cruise[k] = path.sd_peak[k] = 0;
    if (jerked && std::isfinite(sd))
      s_curve(sd, sdd, jerk, path.t_jerk[k], path.t_accel[k], path.t_cruise[k], path.sd_peak[k]);
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
  if (path.sddd_max[k] > 0 && std::isfinite(path.sd_max[k])) return step_jerk_limited(path, pr, dt);
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

bool jerk_limited(const CartesianPath& path) noexcept {
  for (int k = 0; k < path.segments(); ++k)
    if (path.sddd_max[k] > 0) return true;
  return false;
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
