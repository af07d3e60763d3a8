// The arm's inverse kinematics on the shipped robot: its forward kinematics against KDL's own
// solver and a hand-computed pose, round trips over random reachable poses within 0.1 mm and
// 0.1 mrad, the URDF's joint limits (and what ignoring them gives), unreachable targets, the
// null-space preference, and no allocation in set_tool, solve and track.
#include "plugins/robot_model/arm_ik.h"

#include <doctest/doctest.h>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "robot_files.h"
#include "rt/alloc_guard.h"

using namespace crease::robot;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
using Joints = ArmIk::Joints;
using Hand = std::array<double, kHandJoints>;

RobotModel& model() {
  static RobotModel m = RobotModel::load(robot_files::shipped("crease_robot.yaml"));
  return m;
}

// Random arm angles within the middle 90 % of each range, random hand angles within theirs.
Joints random_arm(const RobotModel& m, Side s, std::mt19937& rng) {
  Joints q{};
  for (int j = 0; j < kArmJoints; ++j) {
    const auto& info = m.arm_joints(s)[j];
    const double c = 0.5 * (info.lower_rad + info.upper_rad), h = 0.45 * (info.upper_rad - info.lower_rad);
    q[j] = std::uniform_real_distribution<double>(c - h, c + h)(rng);
  }
  return q;
}
Hand random_hand(const RobotModel& m, Side s, std::mt19937& rng) {
  Hand q{};
  for (int j = 0; j < kHandJoints; ++j) {
    const auto& info = m.hand_joints(s)[j];
    q[j] = std::uniform_real_distribution<double>(info.lower_rad, info.upper_rad)(rng);
  }
  return q;
}

// The tool frame's world pose as robot_model computes it (not the solver's own composition).
KDL::Frame truth(Side s, ToolFrame f, const Joints& q, const Hand& hand) {
  KDL::Frame out;
  REQUIRE(model().tool_pose_m(s, f, q, hand, out));
  return out;
}

// Exact at small differences (KDL's Norm and diff read values under 1e-6 as 0).
double exact_norm(const KDL::Vector& v) { return std::sqrt(KDL::dot(v, v)); }
// The angle between two rotations: |A - B|_F = 2 sqrt(2) sin(theta / 2).
double rot_angle(const KDL::Rotation& a, const KDL::Rotation& b) {
  double f = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f += (a(i, j) - b(i, j)) * (a(i, j) - b(i, j));
  return 2.0 * std::asin(std::min(1.0, std::sqrt(f) / (2.0 * std::sqrt(2.0))));
}

bool within_limits(const ArmIk& ik, const Joints& q) {
  for (int j = 0; j < kArmJoints; ++j)
    if (q[j] < ik.lower()[j] || q[j] > ik.upper()[j]) return false;
  return true;
}

}  // namespace

TEST_CASE("forward kinematics: the flange and the tool frames equal KDL's own solver and a hand-computed pose") {
  ArmIk ik(model(), Side::right);
  KDL::Tree tree;
  REQUIRE(kdl_parser::treeFromFile(model().urdf_file(), tree));
  KDL::Chain chain;
  REQUIRE(tree.getChain("world", "r_flange", chain));
  KDL::ChainFkSolverPos_recursive kdl(chain);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const Joints q = random_arm(model(), Side::right, rng);
    const Hand hand = random_hand(model(), Side::right, rng);
    KDL::JntArray kq(kArmJoints);
    for (int j = 0; j < kArmJoints; ++j) kq(j) = q[j];
    KDL::Frame want;
    REQUIRE(kdl.JntToCart(kq, want) >= 0);
    REQUIRE(ik.set_tool(ToolFrame::flange, q, hand));
    const KDL::Frame got = ik.tool_pose(q);
    CHECK(exact_norm((got.p - want.p)) < 2e-9);  // the URDF's 3.141592654 against the YAML's exact pi
    CHECK(rot_angle(got.M, want.M) < 2e-9);
    // A pad: the flange's pose times the offset set_tool took from the hand equals the pad's chain.
    const ToolFrame f = static_cast<ToolFrame>(trial % kToolFrames);
    REQUIRE(ik.set_tool(f, q, hand));
    const KDL::Frame pad = ik.tool_pose(q), pad_truth = truth(Side::right, f, q, hand);
    CHECK(exact_norm((pad.p - pad_truth.p)) < 1e-12);
    CHECK(rot_angle(pad.M, pad_truth.M) < 1e-12);
  }
  // By hand: S1 = 90 deg turns the arm about the base's z, E1 = 90 deg bends the forearm (E1 ->
  // flange 0.48 + 0.07 m) about the then base y axis. In the base frame (z down from the
  // ceiling mount) Rx(90) takes (0, 0, L) to (0, -L, 0), Rz(90) then to (L, 0, 0): the flange
  // at base (0.55, 0, 0.767), world (0.3 + x, -0.3 - y, 1.0 - z) = (0.85, -0.3, 0.233).
  Joints q{};
  q[0] = 90 * kDeg;
  q[3] = 90 * kDeg;
  const Hand hand{};
  REQUIRE(ik.set_tool(ToolFrame::flange, q, hand));
  const KDL::Frame f = ik.tool_pose(q);
  CHECK(exact_norm((f.p - KDL::Vector(0.85, -0.3, 1.0 - 0.767))) < 1e-9);
  const KDL::Rotation r = KDL::Rotation::RotX(kPi) * KDL::Rotation::RotZ(90 * kDeg) * KDL::Rotation::RotX(90 * kDeg);
  CHECK(rot_angle(f.M, r) < 1e-9);
}

TEST_CASE("the Jacobian at the tool frame equals KDL's ChainJntToJacSolver moved to that point") {
  ArmIk ik(model(), Side::left);
  KDL::ChainJntToJacSolver kdl(ik.arm_chain());
  KDL::ChainFkSolverPos_recursive fk(ik.arm_chain());
  std::mt19937 rng(9);
  for (int trial = 0; trial < 30; ++trial) {
    const Joints q = random_arm(model(), Side::left, rng);
    const Hand hand = random_hand(model(), Side::left, rng);
    REQUIRE(ik.set_tool(static_cast<ToolFrame>(trial % kToolFrames), q, hand));
    KDL::JntArray kq(kArmJoints);
    for (int j = 0; j < kArmJoints; ++j) kq(j) = q[j];
    KDL::Jacobian want(kArmJoints);
    KDL::Frame flange;
    REQUIRE(kdl.JntToJac(kq, want) >= 0);
    REQUIRE(fk.JntToCart(kq, flange) >= 0);
    want.changeRefPoint(flange.M * ik.tool_offset().p);
    const auto got = ik.tool_jacobian(q);
    CHECK((got - want.data).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("round trips over random reachable poses within 0.1 mm and 0.1 mrad, inside the joint limits") {
  std::mt19937 rng(20261202);
  int converged = 0, trials = 0, attempts = 0;
  for (int s = 0; s < kSides; ++s) {
    const Side side = static_cast<Side>(s);
    ArmIk ik(model(), side);
    for (int trial = 0; trial < 150; ++trial) {
      const Joints q_true = random_arm(model(), side, rng);
      const Hand hand = random_hand(model(), side, rng);
      const ToolFrame f = static_cast<ToolFrame>(trial % kToolFrames);
      const KDL::Frame target = truth(side, f, q_true, hand);
      REQUIRE(ik.set_tool(f, ik.options().rest_rad, hand));
      Joints q{};
      const ArmIk::Result r = ik.solve(target, ik.options().rest_rad, q);  // from the rest posture
      ++trials;
      attempts += r.attempts;
      converged += r.converged;
      // Scored against robot_model's forward kinematics, not the solver's own residual.
      const KDL::Frame reached = truth(side, f, q, hand);
      CHECK(r.converged);
      CHECK(1e3 * exact_norm((reached.p - target.p)) < 0.1);
      CHECK(1e3 * rot_angle(reached.M, target.M) < 0.1);
      CHECK(within_limits(ik, q));
    }
  }
  std::printf("ik round trips: %d of %d converged, %.2f attempts per solve\n", converged, trials,
              static_cast<double>(attempts) / trials);
}

TEST_CASE("the limits hold where the unconstrained solver would leave them") {
  // The right elbow narrowed to [20, 137] deg in a copy of the URDF: the solutions with the
  // elbow bent the other way are out of range. Targets come from elbows bent the allowed way.
  const std::string urdf = robot_files::replace(robot_files::read(robot_files::shipped("crease_robot.urdf")),
                                                "lower=\"-2.391101075\"", "lower=\"0.34906585\"",
                                                "<joint name=\"r_E1\"");
  const std::string yaml =
      robot_files::write_robot(robot_files::read(robot_files::shipped("crease_robot.yaml")), "narrow_e1.urdf", urdf);
  const RobotModel narrow = RobotModel::load(yaml);
  REQUIRE(narrow.arm_joints(Side::right)[3].lower_rad == doctest::Approx(20 * kDeg));
  ArmIk::Options loose;
  loose.respect_limits = false;
  loose.restarts = 0;
  ArmIk::Options strict;
  strict.rest_rad[3] = 1.4;
  ArmIk with(narrow, Side::right, strict), without(narrow, Side::right, loose);
  std::mt19937 rng(77);
  int outside_without = 0, outside_with = 0, converged_with = 0, n = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Joints q_true = random_arm(narrow, Side::right, rng);
    const Hand hand{};
    REQUIRE(with.set_tool(ToolFrame::palm_front, q_true, hand));
    REQUIRE(without.set_tool(ToolFrame::palm_front, q_true, hand));
    const KDL::Frame target = with.tool_pose(q_true);
    // From a seed with the elbow bent the wrong way (mirrored): the straight path goes through.
    Joints seed = q_true;
    seed[3] = -q_true[3];
    Joints q1{}, q2{};
    const ArmIk::Result r1 = with.solve(target, seed, q1);
    (void)without.solve(target, seed, q2);
    ++n;
    converged_with += r1.converged;
    outside_with += !within_limits(with, q1);
    outside_without += !within_limits(with, q2);
  }
  std::printf("narrowed elbow: %d of %d unconstrained solutions outside the limits, %d constrained (%d converged)\n",
              outside_without, n, outside_with, converged_with);
  CHECK(outside_with == 0);
  CHECK(outside_without > 0);          // the limits are what keeps the solutions inside
  CHECK(converged_with >= n * 9 / 10);  // and a solution inside is found
}

TEST_CASE("unreachable targets are reported as such") {
  ArmIk ik(model(), Side::right);
  const Hand hand{};
  REQUIRE(ik.set_tool(ToolFrame::ff_pad, ik.options().rest_rad, hand));
  Joints q{};
  // 2.8 m from the shoulder: beyond the arm's 1.3 m reach.
  ArmIk::Result r = ik.solve(KDL::Frame(KDL::Vector(0.3, 2.5, 0.2)), ik.options().rest_rad, q);
  CHECK_FALSE(r.converged);
  CHECK(r.error_m > 0.5);
  CHECK(r.attempts == ik.options().restarts + 1);
  CHECK(within_limits(ik, q));
  // Under the arm's own base, pointing the pad up into the mount: within reach of nothing.
  r = ik.solve(KDL::Frame(KDL::Rotation::RotY(kPi / 2), KDL::Vector(0.3, -0.3, 1.15)), ik.options().rest_rad, q);
  CHECK_FALSE(r.converged);
  CHECK(within_limits(ik, q));
}

TEST_CASE("redundancy: tracking a fixed pose moves the elbow towards the rest posture, the tool stays") {
  ArmIk::Options on;
  on.track_rest_gain = 0.02;  // 40 times the default: 2000 calls show it
  on.track_rest_max_step_rad = 0.01;
  ArmIk ik(model(), Side::right, on);
  const Hand hand{};
  Joints q = {0.4, 0.9, -0.5, 1.0, 0.3, 0.9, 0.2};
  REQUIRE(ik.set_tool(ToolFrame::ff_pad, q, hand));
  const KDL::Frame target = ik.tool_pose(q);
  auto rest_distance = [&](const Joints& a) {
    double d = 0;
    for (int j = 0; j < kArmJoints; ++j) d += (a[j] - ik.options().rest_rad[j]) * (a[j] - ik.options().rest_rad[j]);
    return std::sqrt(d);
  };
  const double d0 = rest_distance(q);
  for (int i = 0; i < 2000; ++i) REQUIRE(ik.track(target, q).converged);
  std::printf("null space: distance to the rest posture %.3f rad -> %.3f rad\n", d0, rest_distance(q));
  CHECK(rest_distance(q) < 0.9 * d0);
  const KDL::Frame reached = truth(Side::right, ToolFrame::ff_pad, q, hand);
  CHECK(1e3 * exact_norm((reached.p - target.p)) < 0.001);
  // Without the null-space term the posture stays where it was.
  ArmIk::Options off;
  off.track_rest_gain = 0;
  ArmIk still(model(), Side::right, off);
  Joints q2 = {0.4, 0.9, -0.5, 1.0, 0.3, 0.9, 0.2};
  REQUIRE(still.set_tool(ToolFrame::ff_pad, q2, hand));
  for (int i = 0; i < 2000; ++i) REQUIRE(still.track(target, q2).converged);
  CHECK(rest_distance(q2) == doctest::Approx(d0).epsilon(1e-6));
}

TEST_CASE("set_tool, solve and track allocate nothing") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  ArmIk ik(model(), Side::left);
  std::mt19937 rng(5);
  const Joints q_true = random_arm(model(), Side::left, rng);
  const Hand hand = random_hand(model(), Side::left, rng);
  Joints q{};
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    for (int i = 0; i < 20; ++i) {
      CHECK(ik.set_tool(static_cast<ToolFrame>(i % kToolFrames), q_true, hand));
      const KDL::Frame target = ik.tool_pose(q_true);
      (void)ik.solve(target, ik.options().rest_rad, q);
      (void)ik.track(target, q);
    }
    (void)ik.solve(KDL::Frame(KDL::Vector(3, 3, 3)), q_true, q);  // every restart of a failure
  }
  CHECK(crease::rt::rt_allocation_count() == before);
}

// The two sides are mirror images across the world's x = 0 plane: the left arm at the right's
// angles with its roll joints (S1, S3, E2, W2: axes along the links) negated, and the left hand at
// the right's own angles, puts every tool frame at the right's mirrored (x -> -x) with its y axis
// reversed (a mirrored frame turned right-handed again: z the pad's normal and x along the finger
// stay). What a fold file for one hand becomes for the other (config/folds/).
TEST_CASE(
    "the left side mirrors the right: negated roll joints, the same hand, every tool frame "
    "mirrored") {
  std::mt19937 rng(11);
  const KDL::Rotation mx(-1, 0, 0, 0, 1, 0, 0, 0, 1), flip_y(1, 0, 0, 0, -1, 0, 0, 0, 1);
  double worst_mm = 0, worst_rad = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Joints qr = random_arm(model(), Side::right, rng);
    const Hand hand = random_hand(model(), Side::right, rng);
    Joints ql = qr;
    for (int j : {0, 2, 4, 6}) ql[j] = -qr[j];
    for (int j = 0; j < kArmJoints; ++j) {  // the mirrored angles are the left's to take
      CHECK(model().arm_joints(Side::left)[j].lower_rad ==
            -model().arm_joints(Side::right)[j].upper_rad);
      CHECK(model().arm_joints(Side::left)[j].upper_rad ==
            -model().arm_joints(Side::right)[j].lower_rad);
    }
    for (int f = 0; f < kToolFrames; ++f) {
      const auto tool = static_cast<ToolFrame>(f);
      const KDL::Frame r = truth(Side::right, tool, qr, hand),
                       l = truth(Side::left, tool, ql, hand);
      const KDL::Vector mirrored(-r.p.x(), r.p.y(), r.p.z());
      worst_mm = std::max(worst_mm, 1000.0 * exact_norm(l.p - mirrored));
      worst_rad = std::max(
          worst_rad, rot_angle(l.M, tool == ToolFrame::flange ? mx * r.M * mx : mx * r.M * flip_y));
    }
  }
  MESSAGE("worst: " << worst_mm << " mm, " << worst_rad << " rad");
  CHECK(worst_mm < 1e-6);
  CHECK(worst_rad < 1e-9);
}
