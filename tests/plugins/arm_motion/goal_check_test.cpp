// The checks of a goal's own content, one reason at a time, in their stated order.
#include "plugins/arm_motion/goal_check.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <initializer_list>

using namespace crease;
using namespace crease::arm_motion;

namespace {
ArmGoal good() {
  ArmGoal g;
  g.point_count = 2;
  g.speed_mm_s = 100;
  g.accel_mm_s2 = 1000;
  g.angular_speed_rad_s = 1;
  g.angular_accel_rad_s2 = 10;
  g.stop_accel_mm_s2 = 2000;
  for (auto& q : g.orientation) q[3] = 1;
  return g;
}
}  // namespace

TEST_CASE("each defect of a goal names its reason") {
  const GoalLimits l;
  CHECK(check_goal(good(), l) == ArmMotionReason::none);
  ArmGoal g = good();
  g.kind = 9;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_points);
  g = good();
  g.frame = ArmGoal::measured;  // the three frames are known
  CHECK(check_goal(g, l) == ArmMotionReason::none);
  g.frame = 3;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_points);
  g = good();
  g.stop_on = 5;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_points);
  g = good();
  g.stop_on = ArmGoal::contact_onset;
  g.stop_fingers = 0;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_points);
  g = good();
  g.tool = 12;
  CHECK(check_goal(g, l) == ArmMotionReason::unknown_tool);
  g = good();
  g.position_mm[1][2] = INFINITY;
  CHECK(check_goal(g, l) == ArmMotionReason::non_finite);
  g = good();
  g.position_mm[2][2] = NAN;  // beyond point_count: not looked at
  CHECK(check_goal(g, l) == ArmMotionReason::none);
  g = good();
  g.orientation[1][0] = NAN;
  CHECK(check_goal(g, l) == ArmMotionReason::non_finite);
  g = good();
  g.angular_accel_rad_s2 = NAN;
  CHECK(check_goal(g, l) == ArmMotionReason::non_finite);
  g = good();
  g.orientation[1][3] = 0.99;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_orientation);
  g = good();
  g.angular_speed_rad_s = 1.6f;  // above 1.5
  CHECK(check_goal(g, l) == ArmMotionReason::bad_limits);
  g = good();
  g.stop_accel_mm_s2 = 6000;  // above 5000
  CHECK(check_goal(g, l) == ArmMotionReason::bad_limits);
  g = good();
  g.speed_mm_s = -1;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_limits);
  ArmGoal stop;
  stop.kind = ArmGoal::stop;  // nothing else read
  stop.speed_mm_s = NAN;
  CHECK(check_goal(stop, l) == ArmMotionReason::none);
}

TEST_CASE("the workspace box holds its faces and refuses what lies beyond or is not a number") {
  const Workspace w;
  const double in[3] = {0, 0, -10}, out[3] = {0, 0, -10.001}, nan[3] = {0, NAN, 0};
  CHECK(w.contains(in));
  CHECK_FALSE(w.contains(out));
  CHECK_FALSE(w.contains(nan));
}

// A lift: each segment rises at least as much as it moves sideways (1 mm slack), the whole
// path more than 1 mm, turning 0.05 rad at most in all.
TEST_CASE("path_is_lift: straight up or steeper than 45 deg, orientation kept") {
  const auto path = [](std::initializer_list<std::array<double, 3>> mm, double turn_rad = 0) {
    CartesianPath p;
    for (const auto& x : mm) {
      for (int c = 0; c < 3; ++c) p.pose[p.count].p_m[c] = x[c] / 1000.0;
      p.pose[p.count].quat[0] = p.count == 0 ? 0.0 : std::sin(turn_rad / 2);  // about x, from the start
      p.pose[p.count].quat[3] = p.count == 0 ? 1.0 : std::cos(turn_rad / 2);
      ++p.count;
    }
    return p;
  };
  CHECK(path_is_lift(path({{0, 0, 0}, {0, 0, 30}})));
  CHECK(path_is_lift(path({{0, 0, 0}, {0.8, 0, 0}, {20, 0, 30}})));  // the commanded-measured slack, then 34 deg
  CHECK(path_is_lift(path({{0, 0, 0}, {0, 0, 30}}, 0.04)));
  CHECK_FALSE(path_is_lift(path({{0, 0, 0}, {0, 0, 30}}, 0.06)));      // turned
  CHECK_FALSE(path_is_lift(path({{0, 0, 0}, {0, 0, -10}})));           // a press
  CHECK_FALSE(path_is_lift(path({{0, 0, 0}, {0, 0, -0.1}, {0, 0, 30}})));  // down first
  CHECK_FALSE(path_is_lift(path({{0, 0, 0}, {32, 0, 30}})));           // flatter than 45 deg
  CHECK_FALSE(path_is_lift(path({{0, 0, 0}, {0, 0, 0.5}})));           // no rise to speak of
  CHECK_FALSE(path_is_lift(path({{0, 0, 0}, {0, 0, NAN}})));
  CHECK_FALSE(path_is_lift(path({{0, 0, 0}})));                        // no motion
}

TEST_CASE("a joints goal: one point in the world or sheet frame, no stop condition; any other interpolation is bad") {
  const GoalLimits l;
  ArmGoal g = good();
  g.interpolation = ArmGoal::joints;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_points);  // two points
  g.point_count = 1;
  CHECK(check_goal(g, l) == ArmMotionReason::none);
  g.frame = ArmGoal::sheet;
  CHECK(check_goal(g, l) == ArmMotionReason::none);
  g.frame = ArmGoal::measured;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_points);
  g.frame = ArmGoal::world;
  g.stop_on = ArmGoal::contact_onset;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_points);
  g.stop_on = ArmGoal::stop_none;
  g.interpolation = 2;
  CHECK(check_goal(g, l) == ArmMotionReason::bad_points);
}
