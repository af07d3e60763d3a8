// The path and its profile on their own: exact arrival, the speed and acceleration limits in
// every cycle (linear and angular), the discrete braking curve, a stop at the stop deceleration,
// zero-length segments, progress and distance to go.
#include "plugins/arm_motion/cartesian_path.h"

#include <doctest/doctest.h>

#include <cmath>
#include <algorithm>
#include <initializer_list>
#include <string>
#include <vector>

using namespace crease::arm_motion;

namespace {

double norm(const KDL::Vector& v) { return std::sqrt(KDL::dot(v, v)); }  // KDL's Norm reads < 1e-6 as 0

CartesianPath two_points(double dx_m, double angle_rad) {
  CartesianPath p;
  p.count = 2;
  p.pose[0] = to_pose(KDL::Frame(KDL::Vector(0.1, 0.2, 0.3)));
  p.pose[1] = to_pose(KDL::Frame(KDL::Rotation::RotZ(angle_rad), KDL::Vector(0.1 + dx_m, 0.2, 0.3)));
  return p;
}

struct Run {
  int cycles = 0;
  double max_v = 0, max_a = 0, max_w = 0, max_alpha = 0;
};

Run run(CartesianPath& path, PathProfile& pr, double dt) {
  Run r;
  KDL::Frame prev = pose_at(path, 0, 0), prev2 = prev;
  double prev_w = 0;
  while (!pr.done && r.cycles < 100000) {
    step_profile(path, pr, dt);
    const KDL::Frame f = pose_at(path, pr.segment, pr.sigma);
    const double v = norm((f.p - prev.p)) / dt;
    const double a = norm(((f.p - prev.p) - (prev.p - prev2.p))) / (dt * dt);
    // Angular speed from a unit lever's tip (KDL::diff rounds rotations under ~1e-6 rad to 0).
    const double w = norm((f.M * KDL::Vector(1, 0, 0) - prev.M * KDL::Vector(1, 0, 0))) / dt;
    r.max_v = std::max(r.max_v, v);
    if (r.cycles >= 1) r.max_a = std::max(r.max_a, a);
    r.max_w = std::max(r.max_w, w);
    r.max_alpha = std::max(r.max_alpha, std::abs(w - prev_w) / dt);
    prev_w = w;
    prev2 = prev;
    prev = f;
    ++r.cycles;
  }
  return r;
}

}  // namespace

TEST_CASE("a segment arrives exactly, within its speed and acceleration in every cycle") {
  CartesianPath path = two_points(0.2, 0.0);
  set_path_limits(path, {0.1, 1.0, 1.0, 10.0, 2.0});
  PathProfile pr;
  const Run r = run(path, pr, 1e-3);
  CHECK(pr.done);
  CHECK(pr.sigma == 1.0);
  CHECK(r.max_v <= 0.1 * (1 + 1e-9));
  CHECK(r.max_v >= 0.1 * (1 - 1e-9));
  CHECK(r.max_a <= 1.0 * (1 + 1e-6));
  // 0.2 m at 0.1 m/s with 0.1 s ramps at 8/9 of 1 m/s^2: about 2.11 s.
  CHECK(r.cycles == doctest::Approx(2112).epsilon(0.01));
}

TEST_CASE("a turn is held to the angular limits; the slower of the two limits sets the pace") {
  CartesianPath path = two_points(0.01, 1.0);  // 10 mm and 1 rad: the rotation is slower
  set_path_limits(path, {0.1, 1.0, 0.5, 2.0, 2.0});
  PathProfile pr;
  const Run r = run(path, pr, 1e-3);
  CHECK(pr.done);
  CHECK(r.max_w <= 0.5 * (1 + 1e-6));
  CHECK(r.max_w >= 0.5 * (1 - 1e-3));
  CHECK(r.max_alpha <= 2.0 * (1 + 1e-3));
  CHECK(r.max_v < 0.1);
}

TEST_CASE("the discrete braking curve stops within the distance, and a stop brakes at the stop deceleration") {
  for (double d : {1e-6, 1e-4, 0.01, 0.37}) {
    const double sdd = 3.0, dt = 1e-3;
    double v = braking_speed(d, sdd, dt), travelled = 0;
    while (v > 0) {
      travelled += v * dt;
      v = std::max(0.0, v - sdd * dt);
    }
    // Whole steps of sdd dt from a fraction overrun by at most sdd dt^2 / 8 (the profile lands
    // exactly on the end instead: step_profile).
    CHECK(travelled <= d + sdd * dt * dt / 8 + 1e-15);
    CHECK(travelled >= d - sdd * dt * dt);  // and it uses the distance
  }
  CartesianPath path = two_points(0.2, 0.0);
  set_path_limits(path, {0.1, 1.0, 1.0, 10.0, 4.0});
  PathProfile pr;
  for (int i = 0; i < 1000; ++i) step_profile(path, pr, 1e-3);
  REQUIRE(pr.sigma_dot * path.length_m[0] == doctest::Approx(0.1));
  pr.stopping = 1;
  double v_prev = pr.sigma_dot * path.length_m[0];
  int n = 0;
  while (!pr.done) {
    const double v = step_profile(path, pr, 1e-3);
    CHECK(v_prev - v <= 4.0 * 1e-3 * (1 + 1e-9));
    CHECK(v_prev - v >= 0);
    v_prev = v;
    ++n;
  }
  CHECK(n == 25);  // 0.1 m/s at 4 m/s^2
  CHECK(pr.sigma < 1.0);
}

TEST_CASE("via points: each segment rests at its end; an empty segment passes in one cycle") {
  CartesianPath path;
  path.count = 4;
  path.pose[0] = to_pose(KDL::Frame(KDL::Vector(0, 0, 0)));
  path.pose[1] = to_pose(KDL::Frame(KDL::Vector(0.05, 0, 0)));
  path.pose[2] = path.pose[1];  // the same point twice
  path.pose[3] = to_pose(KDL::Frame(KDL::Vector(0.05, 0.05, 0)));
  set_path_limits(path, {0.1, 1.0, 1.0, 10.0, 2.0});
  CHECK(std::isinf(path.sd_max[1]));
  PathProfile pr;
  int segment = 0, cycles = 0;
  CHECK(distance_to_go_m(path, pr) == doctest::Approx(0.1));
  while (!pr.done) {
    step_profile(path, pr, 1e-3);
    if (pr.segment != segment) {
      CHECK(pr.sigma_dot == 0.0);
      CHECK(path_progress(path, pr) == doctest::Approx(pr.segment / 3.0));
      segment = pr.segment;
    }
    ++cycles;
  }
  CHECK(segment == 2);
  CHECK(path_progress(path, pr) == 1.0);
  CHECK(distance_to_go_m(path, pr) == 0.0);
}

namespace {

// Finite differences of the sampled poses: the tool point's speed, acceleration and jerk, and
// the rotation angle's about z, the one axis the paths below turn about (at rest before the
// first sample).
struct Diffs {
  double max_v = 0, max_a = 0, max_j = 0, max_w = 0, max_wd = 0, max_wdd = 0;
  std::vector<KDL::Vector> p, tip;  // tip: (yaw, 0, 0)
  double dt = 1e-3;
  void add(const KDL::Frame& f) {
    const KDL::Vector yaw(std::atan2(f.M(1, 0), f.M(0, 0)), 0, 0);
    if (p.empty())
      for (int i = 0; i < 3; ++i) p.push_back(f.p), tip.push_back(yaw);
    p.push_back(f.p);
    tip.push_back(yaw);
    const std::size_t n = p.size() - 1;
    const auto d = [&](const std::vector<KDL::Vector>& x, double& v, double& a, double& j) {
      v = std::max(v, norm(x[n] - x[n - 1]) / dt);
      a = std::max(a, norm(x[n] - 2 * x[n - 1] + x[n - 2]) / (dt * dt));
      j = std::max(j, norm(x[n] - 3 * x[n - 1] + 3 * x[n - 2] - x[n - 3]) / (dt * dt * dt));
    };
    d(p, max_v, max_a, max_j);
    d(tip, max_w, max_wd, max_wdd);
  }
};

// Three segments: 200 mm straight, 50 mm with a 0.8 rad turn, 3 mm (too short to cruise).
CartesianPath three_segments() {
  CartesianPath p;
  p.count = 4;
  p.pose[0] = to_pose(KDL::Frame(KDL::Vector(0.1, 0.2, 0.3)));
  p.pose[1] = to_pose(KDL::Frame(KDL::Vector(0.3, 0.2, 0.3)));
  p.pose[2] = to_pose(KDL::Frame(KDL::Rotation::RotZ(0.8), KDL::Vector(0.3, 0.25, 0.3)));
  p.pose[3] = to_pose(KDL::Frame(KDL::Rotation::RotZ(0.8), KDL::Vector(0.3, 0.25, 0.303)));
  return p;
}

constexpr PathLimits kJerkLimits{0.1, 1.0, 1.0, 10.0, 2.0, 20.0, 150.0, 200.0};

}  // namespace

TEST_CASE("jerk-limited: over a whole motion no cycle exceeds the speed, acceleration or jerk limits, and every via point is "
          "reached exactly at rest (failing variant: jerk limits 0, the acceleration-limited profile)") {
  for (const bool jerk : {true, false}) {
    CAPTURE(jerk);
    CartesianPath path = three_segments();
    PathLimits l = kJerkLimits;
    if (!jerk) l.jerk_m_s3 = l.angular_jerk_rad_s3 = l.stop_jerk_m_s3 = 0;
    set_path_limits(path, l);
    CHECK(jerk_limited(path) == jerk);
    PathProfile pr;
    Diffs d;
    d.add(pose_at(path, 0, 0));
    int segment = 0, cycles = 0;
    while (!pr.done && cycles < 100000) {
      step_profile(path, pr, 1e-3);
      d.add(pose_at(path, pr.segment, pr.sigma));
      if (pr.segment != segment) {  // the previous segment ended at rest on its point
        CHECK(norm(d.p.back() - KDL::Vector(path.pose[pr.segment].p_m[0], path.pose[pr.segment].p_m[1],
                                                     path.pose[pr.segment].p_m[2])) == 0.0);
        segment = pr.segment;
      }
      ++cycles;
    }
    for (int i = 0; i < 3; ++i) d.add(pose_at(path, pr.segment, pr.sigma));  // at rest after it
    REQUIRE(pr.done);
    CHECK(pr.sigma == 1.0);
    CHECK(segment == 2);
    MESSAGE(std::string(jerk ? "jerk-limited" : "acceleration-limited") << ": " << cycles << " cycles; at most " << d.max_v << " m/s, "
            << d.max_a << " m/s^2, " << d.max_j << " m/s^3; rotation " << d.max_w << " rad/s, " << d.max_wd
            << " rad/s^2, " << d.max_wdd << " rad/s^3");
    CHECK(d.max_v <= 0.1 * (1 + 1e-9));
    CHECK(d.max_a <= 1.0 * (1 + 1e-6));
    CHECK(d.max_w <= 1.0 * (1 + 1e-6));
    CHECK(d.max_wd <= 10.0 * (1 + 1e-6));
    if (jerk) {
      CHECK(d.max_j <= 20.0 * (1 + 1e-6));
      CHECK(d.max_j >= 19.0);  // and uses it
      CHECK(d.max_wdd <= 150.0 * (1 + 1e-6));
    } else {
      CHECK(d.max_j > 20.0 * 10);  // the acceleration steps: about a / dt
    }
  }
}

TEST_CASE("jerk-limited stop: from accelerating, cruising or braking, it stays within the stop deceleration and jerk and "
          "comes to rest; from a cruise its first cycle is already slower") {
  for (const int at : {40, 1000, 2030, 2090}) {  // accelerating, cruising, braking, nearly at the first point
    CAPTURE(at);
    CartesianPath path = three_segments();
    set_path_limits(path, kJerkLimits);
    PathProfile pr;
    Diffs d;
    d.add(pose_at(path, 0, 0));
    for (int i = 0; i < at && !pr.done; ++i) {
      step_profile(path, pr, 1e-3);
      d.add(pose_at(path, pr.segment, pr.sigma));
    }
    REQUIRE(pr.segment == 0);
    const double v_before = pr.sigma_dot * path.length_m[0];
    const double a_before = pr.sigma_ddot * path.length_m[0];
    pr.stopping = 1;
    Diffs s = d;  // the differences from the stop on
    s.max_v = s.max_a = s.max_j = 0;
    const double v_first = step_profile(path, pr, 1e-3);
    s.add(pose_at(path, pr.segment, pr.sigma));
    int n = 1;
    while (!pr.done && n < 10000) {
      step_profile(path, pr, 1e-3);
      s.add(pose_at(path, pr.segment, pr.sigma));
      ++n;
    }
    for (int i = 0; i < 3; ++i) s.add(pose_at(path, pr.segment, pr.sigma));
    REQUIRE(pr.done);
    CHECK(pr.sigma_dot == 0.0);
    CHECK(pr.segment == 0);
    CHECK(pr.sigma <= 1.0);
    MESSAGE("stop from " << v_before << " m/s, " << a_before << " m/s^2: " << n << " cycles, at most " << s.max_a << " m/s^2, "
                         << s.max_j << " m/s^3");
    CHECK(s.max_a <= 2.0 * (1 + 1e-6));
    CHECK(s.max_j <= 200.0 * (1 + 1e-6));
    if (at == 1000) {
      CHECK(a_before == 0.0);
      CHECK(v_first < v_before);
      // Braking at 2 m/s^2 after a 10 ms jerk ramp: v^2 / 2a + v a / 2j, within one cycle.
      const double d_stop = v_before * v_before / 4.0 + v_before * 2.0 / 400.0;
      const double travelled = (pr.sigma - pr.stop_s0) * path.length_m[0];
      CHECK(travelled <= d_stop + 1e-9);
      CHECK(travelled >= d_stop - v_before * 1e-3);
    }
  }
}
