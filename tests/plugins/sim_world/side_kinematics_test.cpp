// The world's one-pass kinematics against robot_model's KDL chains (the same poses), its hand
// Jacobian against finite differences, the wrench form against the point forces, and no
// allocation in a step's updates.
#include "plugins/sim_world/side_kinematics.h"

#include <doctest/doctest.h>

#include <array>
#include <string>

#include "rt/alloc_guard.h"
#include "scene.h"

using namespace scene;

namespace {

// A configuration spread over every joint's range (deterministic).
void config(const robot::RobotModel& m, robot::Side s, int k, ArmQ& arm, HandQ& hand) {
  SplitMix64 rng(1000 + static_cast<std::uint64_t>(k));
  const auto& aj = m.arm_joints(s);
  const auto& hj = m.hand_joints(s);
  for (int j = 0; j < robot::kArmJoints; ++j)
    arm[j] = aj[j].lower_rad + (aj[j].upper_rad - aj[j].lower_rad) * 0.5 * (1 + rng.symmetric());
  for (int j = 0; j < robot::kHandJoints; ++j)
    hand[j] = hj[j].lower_rad + (hj[j].upper_rad - hj[j].lower_rad) * 0.5 * (1 + rng.symmetric());
}

}  // namespace

TEST_CASE("every tool frame where robot_model's KDL chain puts it, on both sides") {
  auto m = robot::RobotModel::load(std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml");
  for (int sd = 0; sd < robot::kSides; ++sd) {
    const auto side = static_cast<robot::Side>(sd);
    SideKinematics k(m, side);
    const std::string& prefix = m.params().side(side).prefix;
    for (int c = 0; c < 20; ++c) {
      ArmQ arm;
      HandQ hand;
      config(m, side, c, arm, hand);
      k.update_rt(arm, hand);
      for (int f = 0; f < robot::kToolFrames; ++f) {
        KDL::Frame kdl;
        REQUIRE(m.tool_pose_m(side, static_cast<robot::ToolFrame>(f), arm, hand, kdl));
        const int link = k.link_index(prefix + std::string(robot::kToolFrameLinks[f]));
        REQUIRE(link >= 0);
        const Pose& p = k.link_pose(link);
        CHECK(p.t.x == doctest::Approx(1000 * kdl.p.x()).epsilon(1e-9).scale(1.0));
        CHECK(p.t.y == doctest::Approx(1000 * kdl.p.y()).epsilon(1e-9).scale(1.0));
        CHECK(p.t.z == doctest::Approx(1000 * kdl.p.z()).epsilon(1e-9).scale(1.0));
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) CHECK(p.r[3 * i + j] == doctest::Approx(kdl.M(i, j)).epsilon(1e-12).scale(1.0));
      }
    }
  }
}

TEST_CASE("update_rt recomputes what moved: many calls, one joint at a time, equal a fresh pose") {
  // A step poses a side three times, the arm unchanged; only the segments under a changed joint
  // are recomputed. Over a run of calls, each changing one arm or hand joint (or none), every
  // link pose and joint axis equals that of a kinematics posed once at the same angles.
  const auto& m = robot_model();
  SideKinematics k(m, robot::Side::left);
  ArmQ arm;
  HandQ hand;
  config(m, robot::Side::left, 7, arm, hand);
  SplitMix64 rng(77);
  for (int call = 0; call < 60; ++call) {
    const int which = call % 3 == 2
                          ? -1
                          : static_cast<int>(rng.next() % (robot::kArmJoints + robot::kHandJoints));
    if (which >= 0 && which < robot::kArmJoints) arm[which] += 0.05 * rng.symmetric();
    if (which >= robot::kArmJoints) hand[which - robot::kArmJoints] += 0.05 * rng.symmetric();
    k.update_rt(arm, hand);
    SideKinematics fresh(m, robot::Side::left);
    fresh.update_rt(arm, hand);
    for (int link = 0; link < fresh.link_count(); ++link) {
      const Pose &a = k.link_pose(link), &b = fresh.link_pose(link);
      REQUIRE(a.t.x == b.t.x);
      REQUIRE(a.t.y == b.t.y);
      REQUIRE(a.t.z == b.t.z);
      for (int e = 0; e < 9; ++e) REQUIRE(a.r[e] == b.r[e]);
      // The joint axes and origins, as the hand Jacobian reads them.
      std::array<double, robot::kHandJoints> ga{}, gb{};
      k.add_hand_jacobian_transpose(link, b.t, {1, 2, 3}, ga);
      fresh.add_hand_jacobian_transpose(link, b.t, {1, 2, 3}, gb);
      REQUIRE(ga == gb);
    }
  }
}

TEST_CASE("the hand Jacobian: finite differences, its transpose, and the wrench form") {
  const auto& m = robot_model();
  SideKinematics k(m, robot::Side::right);
  ArmQ arm;
  HandQ hand;
  config(m, robot::Side::right, 7, arm, hand);
  const int link = k.link_index("r_ffdistal");
  REQUIRE(k.moved_by_hand(link));
  CHECK_FALSE(k.moved_by_hand(k.link_index("r_forearm")));
  k.update_rt(arm, hand);
  const Vec3 local{0, -8.5, 12};  // a point on the pad, in the link's frame
  const Pose p0 = k.link_pose(link);
  const Vec3 point = p0.apply(local);
  constexpr double h = 1e-6;
  for (int j = 0; j < robot::kHandJoints; ++j) {
    HandQ dq{};
    dq[j] = 1.0;
    const Vec3 analytic = k.hand_jacobian_times(link, point, dq);
    HandQ q2 = hand;
    q2[j] += h;
    SideKinematics k2(m, robot::Side::right);
    k2.update_rt(arm, q2);
    const Vec3 numeric = (1.0 / h) * (k2.link_pose(link).apply(local) - point);
    CHECK(analytic.x == doctest::Approx(numeric.x).epsilon(1e-4).scale(1.0));
    CHECK(analytic.y == doctest::Approx(numeric.y).epsilon(1e-4).scale(1.0));
    CHECK(analytic.z == doctest::Approx(numeric.z).epsilon(1e-4).scale(1.0));
    // J^T f . e_j = f . J e_j
    const Vec3 f{0.3, -0.2, 0.9};
    std::array<double, robot::kHandJoints> g{};
    k.add_hand_jacobian_transpose(link, point, f, g);
    CHECK(g[j] == doctest::Approx(crease::sheet::dot(f, analytic)).epsilon(1e-12).scale(1.0));
  }
  // Two point forces as one wrench about the world origin.
  const Vec3 p1 = p0.apply({0, -8, 5}), p2 = p0.apply({2, -8, 15}), f1{0.1, 0, -1}, f2{0, 0.4, -0.5};
  std::array<double, robot::kHandJoints> a{}, b{};
  k.add_hand_jacobian_transpose(link, p1, f1, a);
  k.add_hand_jacobian_transpose(link, p2, f2, a);
  k.add_hand_wrench_transpose(link, f1 + f2, crease::sheet::cross(p1, f1) + crease::sheet::cross(p2, f2), b);
  for (int j = 0; j < robot::kHandJoints; ++j) CHECK(b[j] == doctest::Approx(a[j]).epsilon(1e-9).scale(1.0));
}

TEST_CASE("update_rt and the Jacobian allocate nothing") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  const auto& m = robot_model();
  SideKinematics k(m, robot::Side::left);
  ArmQ arm{};
  HandQ hand{};
  std::array<double, robot::kHandJoints> g{};
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    for (int i = 0; i < 500; ++i) {
      hand[3] = 0.001 * i;
      k.update_rt(arm, hand);
      k.add_hand_jacobian_transpose(k.link_count() - 1, {0, 0, 0}, {0, 0, 1}, g);
    }
  }
  CHECK(crease::rt::rt_allocation_count() == before);
}
