// A tool chain on a small chain written inline: its pose by hand, the mimic rule, the
// checks at construction, and no allocation in pose_m.
#include "plugins/robot_model/tool_chain.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <string>

#include "rt/alloc_guard.h"
#include "support/abort_message.h"

using namespace crease::robot;

namespace {

// base --(fixed, +0.1 z)--> a --(rot x, arm joint 2)--> b: 0.2 along z
//   --(rot x, hand joint 5)--> c: 0.1 along z --(rot x, mimic of hand 5: 0.5 q + 0.1)--> tip 0.05
KDL::Chain small_chain() {
  KDL::Chain c;
  c.addSegment(KDL::Segment("a", KDL::Joint("fix", KDL::Joint::None), KDL::Frame(KDL::Vector(0, 0, 0.1))));
  c.addSegment(KDL::Segment("b", KDL::Joint("j_arm", KDL::Joint::RotX), KDL::Frame(KDL::Vector(0, 0, 0.2))));
  c.addSegment(KDL::Segment("c", KDL::Joint("j_hand", KDL::Joint::RotX), KDL::Frame(KDL::Vector(0, 0, 0.1))));
  c.addSegment(KDL::Segment("tip", KDL::Joint("j_mimic", KDL::Joint::RotX), KDL::Frame(KDL::Vector(0, 0, 0.05))));
  return c;
}

std::vector<JointSource> small_sources() {
  return {{JointSource::arm, 2, 1.0, 0.0}, {JointSource::hand, 5, 1.0, 0.0}, {JointSource::hand, 5, 0.5, 0.1}};
}

}  // namespace

TEST_CASE("the tip's pose by hand: each joint reads its arm or hand angle, a mimic its master's") {
  ToolChain t("tip", small_chain(), small_sources());
  CHECK(t.tip() == "tip");
  std::array<double, kArmJoints> arm{};
  std::array<double, kHandJoints> hand{};
  arm[2] = 0.3;
  hand[5] = 0.4;
  KDL::Frame f;
  REQUIRE(t.pose_m(arm, hand, f));
  // Rotations about x: (0, 0, l) turned by a lies at (0, -l sin a, l cos a).
  const double a1 = 0.3, a2 = 0.3 + 0.4, a3 = 0.3 + 0.4 + (0.5 * 0.4 + 0.1);
  const double y = -0.2 * std::sin(a1) - 0.1 * std::sin(a2) - 0.05 * std::sin(a3);
  const double z = 0.1 + 0.2 * std::cos(a1) + 0.1 * std::cos(a2) + 0.05 * std::cos(a3);
  CHECK(f.p.x() == doctest::Approx(0.0));
  CHECK(f.p.y() == doctest::Approx(y).epsilon(1e-12));
  CHECK(f.p.z() == doctest::Approx(z).epsilon(1e-12));
  double angle = 0;
  KDL::Vector axis = f.M.GetRot();
  angle = axis.Norm();
  CHECK(angle == doctest::Approx(a3).epsilon(1e-12));
  KDL::JntArray q(3);
  t.chain_angles(arm, hand, q);
  CHECK(q(0) == 0.3);
  CHECK(q(1) == 0.4);
  CHECK(q(2) == doctest::Approx(0.3));
}

TEST_CASE("sources that do not match the chain are a bug (demand tier): the process aborts") {
  using crease::testing::abort_message;
  CHECK(abort_message([] {
          ToolChain("tip", small_chain(), {{JointSource::arm, 0, 1, 0}});
        }).find("one source per chain joint") != std::string::npos);
  auto bad = small_sources();
  bad[1].index = kHandJoints;
  CHECK(abort_message([&] { ToolChain("tip", small_chain(), bad); }).find("source index") !=
        std::string::npos);
  bad = small_sources();
  bad[0].index = kArmJoints;
  CHECK(abort_message([&] { ToolChain("tip", small_chain(), bad); }).find("source index") !=
        std::string::npos);
  // The matching sources build the chain (the same calls without the defects do not abort).
  CHECK(abort_message([] { ToolChain("tip", small_chain(), small_sources()); }) ==
        "(did not abort)");
}

TEST_CASE("pose_m allocates nothing; constructing a chain does") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  std::array<double, kArmJoints> arm{};
  std::array<double, kHandJoints> hand{};
  ToolChain t("tip", small_chain(), small_sources());
  KDL::Frame f;
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    for (int i = 0; i < 1000; ++i) {
      arm[2] = 0.001 * i;
      CHECK(t.pose_m(arm, hand, f));
    }
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  {
    crease::rt::ScopedRtMark rt;
    ToolChain other("tip", small_chain(), small_sources());
    CHECK(other.pose_m(arm, hand, f));
  }
  CHECK(crease::rt::rt_allocation_count() > before);
}
