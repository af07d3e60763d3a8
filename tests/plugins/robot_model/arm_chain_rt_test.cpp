// The IK's pass down the arm chain against KDL on the shipped robot: the flange pose as KDL's
// ChainFkSolverPos_recursive, each joint's axis as the angular rows of KDL's Jacobian, over random
// angles of both arms; a chain it cannot take (a prismatic joint, too few joints) is refused
// at construction; the pass allocates nothing.
#include "plugins/robot_model/arm_chain_rt.h"

#include <doctest/doctest.h>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <random>
#include <string>

#include "core/errors.h"
#include "plugins/robot_model/robot_model.h"
#include "robot_files.h"
#include "rt/alloc_guard.h"

using namespace crease::robot;

TEST_CASE("the pass gives KDL's flange pose and joint axes at random angles of both arms") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  const RobotModel m = RobotModel::load(robot_files::shipped("crease_robot.yaml"));
  std::mt19937 rng(5);
  for (const Side side : {Side::right, Side::left}) {
    const std::string flange = m.params().side(side).prefix + "flange";
    const KDL::Chain chain = m.make_chain(side, flange).chain();
    const ArmChainRt fast(chain);
    KDL::ChainFkSolverPos_recursive fk(chain);
    KDL::ChainJntToJacSolver jac(chain);
    for (int trial = 0; trial < 200; ++trial) {
      std::array<double, kArmJoints> q{};
      KDL::JntArray kq(kArmJoints);
      for (int j = 0; j < kArmJoints; ++j) {
        const auto& info = m.arm_joints(side)[j];
        q[static_cast<std::size_t>(j)] =
            std::uniform_real_distribution<double>(info.lower_rad, info.upper_rad)(rng);
        kq(j) = q[static_cast<std::size_t>(j)];
      }
      std::array<Eigen::Vector3d, kArmJoints> axis, origin;
      Eigen::Isometry3d got;
      const auto before = crease::rt::rt_allocation_count();
      {
        crease::rt::ScopedRtMark rt;
        fast.pass(q, axis, origin, got);
      }
      CHECK(crease::rt::rt_allocation_count() == before);
      KDL::Frame want;
      REQUIRE(fk.JntToCart(kq, want) >= 0);
      KDL::Jacobian j(kArmJoints);
      REQUIRE(jac.JntToJac(kq, j) >= 0);
      double worst_p = 0, worst_r = 0, worst_axis = 0, worst_lin = 0;
      for (int r = 0; r < 3; ++r) {
        worst_p = std::max(worst_p, std::abs(got.translation()(r) - want.p(r)));
        for (int c = 0; c < 3; ++c)
          worst_r = std::max(worst_r, std::abs(got.linear()(r, c) - want.M(r, c)));
      }
      for (int k = 0; k < kArmJoints; ++k) {
        // KDL's columns at the flange's origin: [a x (p_flange - o); a].
        const Eigen::Vector3d lin = axis[static_cast<std::size_t>(k)].cross(
            got.translation() - origin[static_cast<std::size_t>(k)]);
        for (int r = 0; r < 3; ++r) {
          worst_axis =
              std::max(worst_axis, std::abs(axis[static_cast<std::size_t>(k)](r) - j(3 + r, k)));
          worst_lin = std::max(worst_lin, std::abs(lin(r) - j(r, k)));
        }
      }
      CHECK(worst_p < 1e-12);
      CHECK(worst_r < 1e-12);
      CHECK(worst_axis < 1e-12);
      CHECK(worst_lin < 1e-12);
    }
  }
}

TEST_CASE("a chain with a prismatic joint or without seven revolute joints is refused") {
  KDL::Chain six;
  for (int j = 0; j < 6; ++j)
    six.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ), KDL::Frame(KDL::Vector(0, 0, 0.1))));
  CHECK_THROWS_WITH_AS(ArmChainRt{six}, doctest::Contains("6 revolute joints, not 7"),
                       crease::ConfigError);
  KDL::Chain slide = six;
  slide.addSegment(
      KDL::Segment(KDL::Joint("s", KDL::Joint::TransZ), KDL::Frame(KDL::Vector(0, 0, 0.1))));
  CHECK_THROWS_WITH_AS(ArmChainRt{slide}, doctest::Contains("joint 's' is not revolute"),
                       crease::ConfigError);
}
