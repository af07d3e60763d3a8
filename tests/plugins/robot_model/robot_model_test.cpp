// The shipped robot (config/robot/): joints, limits, forward kinematics against hand-computed
// poses and against KDL's own solver on an independently parsed tree, mounting, collision
// shapes and their friction, load errors, and no allocation in the forward kinematics.
#include "plugins/robot_model/robot_model.h"

#include <doctest/doctest.h>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl_parser/kdl_parser.hpp>

#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>

#include "core/errors.h"
#include "robot_files.h"
#include "rt/alloc_guard.h"

using namespace crease::robot;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

RobotModel shipped_model() { return RobotModel::load(robot_files::shipped("crease_robot.yaml")); }

std::array<double, kArmJoints> zero_arm() { return {}; }
std::array<double, kHandJoints> zero_hand() { return {}; }

int hand_index(std::string_view name) {
  for (int i = 0; i < kHandJoints; ++i) {
    if (kHandJointNames[i] == name) return i;
  }
  FAIL("no hand joint " << name);
  return -1;
}

// |a - b| for positions (m) and the largest rotation-matrix entry difference. The norm is
// computed here: KDL's Vector::Norm() reads anything under 1e-6 as 0.
void check_frame(const KDL::Frame& got, const KDL::Vector& p, const KDL::Rotation& r, double tol) {
  CHECK(std::sqrt(KDL::dot(got.p - p, got.p - p)) < tol);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) CHECK(std::abs(got.M(i, j) - r(i, j)) < tol);
  }
}

// Hand computation of the shipped URDF's numbers (see its header comment): the right arm's
// base hangs at (0.3, -0.3, 1.0) m, rotated 180 deg about x, so base (x, y, z) is world
// (0.3 + x, -0.3 - y, 1.0 - z). In the base frame at zero the arm and hand stretch along +z.
KDL::Vector right_base_to_world(double x, double y, double z) { return {0.3 + x, -0.3 - y, 1.0 - z}; }
// A rotation about axes of the right arm's base frame, as a rotation of world vectors.
KDL::Rotation in_world(const KDL::Rotation& in_base) {
  return KDL::Rotation::RotX(kPi) * in_base * KDL::Rotation::RotX(kPi).Inverse();
}
constexpr double kFlangeZ = 0.317 + 0.450 + 0.480 + 0.070;                 // PA-10
constexpr double kFfKnuckleZ = kFlangeZ + 0.21301 + 0.034 + 0.095;         // forearm, wrist, palm
constexpr double kFfKnuckleY = -0.010;                                     // WRJ2's offset
constexpr double kFfKnuckleX = 0.033;
constexpr double kPadDepth = 0.0085, kPadAlong = 0.012;  // pad origin in the distal frame (y, z)

}  // namespace

TEST_CASE("the shipped robot loads: 7 arm joints and 20 hand joints per side, in the drivers' order") {
  const RobotModel m = shipped_model();
  for (int s = 0; s < kSides; ++s) {
    const Side side = static_cast<Side>(s);
    const std::string prefix = s == 0 ? "r_" : "l_";
    CHECK(m.params().side(side).prefix == prefix);
    const auto& arm = m.arm_joints(side);
    REQUIRE(arm.size() == 7);
    const char* arm_names[] = {"S1", "S2", "S3", "E1", "E2", "W1", "W2"};
    for (int i = 0; i < 7; ++i) CHECK(arm[i].name == prefix + arm_names[i]);
    // drivers/README.md §3, written out here so a reordering of either shows.
    const char* hand_names[] = {"WRJ2", "WRJ1", "FFJ4", "FFJ3", "FFJ2", "MFJ4", "MFJ3",
                                "MFJ2", "RFJ4", "RFJ3", "RFJ2", "LFJ5", "LFJ4", "LFJ3",
                                "LFJ2", "THJ5", "THJ4", "THJ3", "THJ2", "THJ1"};
    const auto& hand = m.hand_joints(side);
    REQUIRE(hand.size() == 20);
    for (int i = 0; i < 20; ++i) CHECK(hand[i].name == prefix + hand_names[i]);
    // The coupled distal joints of the four fingers follow their J2 one to one.
    const auto& mimics = m.hand_mimics(side);
    REQUIRE(mimics.size() == 4);
    for (const auto& mj : mimics) {
      const std::string finger = mj.name.substr(prefix.size(), 2);
      CHECK(mj.name == prefix + finger + "J1");
      CHECK(hand[mj.master].name == prefix + finger + "J2");
      CHECK(mj.multiplier == 1.0);
      CHECK(mj.offset == 0.0);
    }
    // 7 + 20 + 4 movable joints per side, nothing else.
    CHECK(m.tree().getNrOfJoints() == 2 * (7 + 20 + 4));
  }
}

TEST_CASE("joint limits: the PA-10's and the Shadow hand's") {
  const RobotModel m = shipped_model();
  const double arm_deg[] = {177, 94, 174, 137, 255, 165, 255};
  for (int s = 0; s < kSides; ++s) {
    const auto& arm = m.arm_joints(static_cast<Side>(s));
    for (int i = 0; i < 7; ++i) {
      CHECK(arm[i].lower_rad == doctest::Approx(-arm_deg[i] * kDeg).epsilon(1e-8));
      CHECK(arm[i].upper_rad == doctest::Approx(arm_deg[i] * kDeg).epsilon(1e-8));
      CHECK(arm[i].velocity_rad_s == doctest::Approx(kPi).epsilon(1e-8));  // 180 deg/s
    }
    const auto& hand = m.hand_joints(static_cast<Side>(s));
    const auto limits = [&](std::string_view j, double lo_deg, double hi_deg) {
      const JointInfo& info = hand[hand_index(j)];
      CHECK(info.lower_rad == doctest::Approx(lo_deg * kDeg).epsilon(1e-8));
      CHECK(info.upper_rad == doctest::Approx(hi_deg * kDeg).epsilon(1e-8));
    };
    limits("WRJ2", -30, 10);
    limits("WRJ1", -40, 28);
    limits("FFJ4", -20, 20);
    limits("FFJ3", -15, 90);
    limits("MFJ2", 0, 90);
    limits("LFJ5", 0, 45);
    limits("THJ5", -60, 60);
    limits("THJ4", 0, 70);
    limits("THJ3", -12, 12);
    limits("THJ2", -40, 40);
    limits("THJ1", -15, 90);
  }
}

TEST_CASE("forward kinematics of a fingertip pad equals the hand-computed pose") {
  RobotModel m = shipped_model();
  auto arm = zero_arm();
  auto hand = zero_hand();
  KDL::Frame pad;
  // Pad frame at zero: x along the finger (base +z), y = -(base x), z the outward normal, on the
  // palmar side (base -y). In the world: x down, y = -x, z = +y.
  const KDL::Rotation pad_at_zero(0, -1, 0,  //
                                  0, 0, 1,   //
                                  -1, 0, 0);

  SUBCASE("all joints zero: arm and hand hang straight down") {
    REQUIRE(m.tool_pose_m(Side::right, ToolFrame::ff_pad, arm, hand, pad));
    const double z = kFfKnuckleZ + 0.045 + 0.025 + kPadAlong;
    check_frame(pad, right_base_to_world(kFfKnuckleX, kFfKnuckleY - kPadDepth, z), pad_at_zero, 1e-9);
    KDL::Frame flange;
    REQUIRE(m.tool_pose_m(Side::right, ToolFrame::flange, arm, hand, flange));
    check_frame(flange, right_base_to_world(0, 0, kFlangeZ), KDL::Rotation::RotX(kPi), 1e-9);
  }
  SUBCASE("the elbow E1 at 90 deg: the forearm and hand turn about the base's x axis") {
    arm[3] = 90 * kDeg;
    REQUIRE(m.tool_pose_m(Side::right, ToolFrame::ff_pad, arm, hand, pad));
    // From E1 (base z = 0.767) the pad is at (0.033, -0.0185, 0.974...) at zero; Rx(90) takes
    // (x, y, z) to (x, -z, y).
    const double e1 = 0.317 + 0.450;
    const double along = kFfKnuckleZ + 0.045 + 0.025 + kPadAlong - e1;
    const double y0 = kFfKnuckleY - kPadDepth;
    check_frame(pad, right_base_to_world(kFfKnuckleX, -along, e1 + y0),
                in_world(KDL::Rotation::RotX(90 * kDeg)) * pad_at_zero, 1e-9);
    // The pad now faces up (world +z), the finger points away from the robot (world +y).
    CHECK(pad.M.UnitZ().z() == doctest::Approx(1.0));
    CHECK(pad.M.UnitX().y() == doctest::Approx(1.0));
  }
  SUBCASE("FFJ3 (MCP) at 90 deg: the fingertip pad swings to the palm's side") {
    hand[hand_index("FFJ3")] = 90 * kDeg;
    REQUIRE(m.tool_pose_m(Side::right, ToolFrame::ff_pad, arm, hand, pad));
    // About base x by 90 deg from the knuckle: (0, -0.0085, 0.082) -> (0, -0.082, -0.0085).
    const double along = 0.045 + 0.025 + kPadAlong;
    check_frame(pad,
                right_base_to_world(kFfKnuckleX, kFfKnuckleY - along, kFfKnuckleZ - kPadDepth),
                in_world(KDL::Rotation::RotX(90 * kDeg)) * pad_at_zero, 1e-9);
  }
  SUBCASE("FFJ2 at 45 deg also bends the coupled FFJ1 by 45 deg") {
    const double t = 45 * kDeg;
    hand[hand_index("FFJ2")] = t;
    REQUIRE(m.tool_pose_m(Side::right, ToolFrame::ff_pad, arm, hand, pad));
    // Base frame, rotations about x: R(a)(0, y, z) = (0, y cos a - z sin a, y sin a + z cos a).
    const double j2_z = kFfKnuckleZ + 0.045;
    const double y = kFfKnuckleY - 0.025 * std::sin(t) + (-kPadDepth * std::cos(2 * t) - kPadAlong * std::sin(2 * t));
    const double z = j2_z + 0.025 * std::cos(t) + (-kPadDepth * std::sin(2 * t) + kPadAlong * std::cos(2 * t));
    check_frame(pad, right_base_to_world(kFfKnuckleX, y, z),
                in_world(KDL::Rotation::RotX(2 * t)) * pad_at_zero, 1e-9);
  }
}

TEST_CASE("every tool frame equals KDL's ChainFkSolverPos_recursive on a tree parsed by kdl_parser") {
  RobotModel m = shipped_model();
  KDL::Tree tree;
  REQUIRE(kdl_parser::treeFromFile(m.urdf_file(), tree));  // the URDF's own mounting = the YAML's
  std::mt19937 rng(12);
  for (int trial = 0; trial < 20; ++trial) {
    for (int s = 0; s < kSides; ++s) {
      const Side side = static_cast<Side>(s);
      std::array<double, kArmJoints> arm{};
      std::array<double, kHandJoints> hand{};
      std::map<std::string, double> by_name;
      for (int i = 0; i < kArmJoints; ++i) {
        const auto& j = m.arm_joints(side)[i];
        arm[i] = std::uniform_real_distribution<double>(j.lower_rad, j.upper_rad)(rng);
        by_name[j.name] = arm[i];
      }
      for (int i = 0; i < kHandJoints; ++i) {
        const auto& j = m.hand_joints(side)[i];
        hand[i] = std::uniform_real_distribution<double>(j.lower_rad, j.upper_rad)(rng);
        by_name[j.name] = hand[i];
      }
      const std::string prefix = m.params().side(side).prefix;
      for (const char* f : {"FF", "MF", "RF", "LF"}) {
        by_name[prefix + f + "J1"] = by_name[prefix + f + "J2"];  // the URDF's <mimic>
      }
      for (int f = 0; f < kToolFrames; ++f) {
        const std::string tip = prefix + std::string(kToolFrameLinks[f]);
        KDL::Chain chain;
        REQUIRE(tree.getChain("world", tip, chain));
        KDL::JntArray q(chain.getNrOfJoints());
        unsigned k = 0;
        for (const auto& seg : chain.segments) {
          if (seg.getJoint().getType() == KDL::Joint::None) continue;
          REQUIRE(by_name.count(seg.getJoint().getName()) == 1);
          q(k++) = by_name[seg.getJoint().getName()];
        }
        KDL::ChainFkSolverPos_recursive kdl(chain);
        KDL::Frame want, got;
        REQUIRE(kdl.JntToCart(q, want) >= 0);
        REQUIRE(m.tool_pose_m(side, static_cast<ToolFrame>(f), arm, hand, got));
        // 2e-9: the URDF writes the mounting's 180 deg as 3.141592654, the YAML's is exact
        // (4e-10 rad over the 1.7 m from the mount to a fingertip).
        check_frame(got, want.p, want.M, 2e-9);
      }
    }
  }
}

TEST_CASE("the left hand mirrors the right in x at zero; pads face the palm's side on both") {
  RobotModel m = shipped_model();
  const auto arm = zero_arm();
  const auto hand = zero_hand();
  for (int f = 0; f < kFingertips; ++f) {
    KDL::Frame r, l, r_palm, l_palm;
    REQUIRE(m.tool_pose_m(Side::right, pad_frame(f), arm, hand, r));
    REQUIRE(m.tool_pose_m(Side::left, pad_frame(f), arm, hand, l));
    REQUIRE(m.tool_pose_m(Side::right, ToolFrame::palm_front, arm, hand, r_palm));
    REQUIRE(m.tool_pose_m(Side::left, ToolFrame::palm_front, arm, hand, l_palm));
    // Relative to each arm's base (mirrored in x: right at +0.3, left at -0.3).
    CHECK(r.p.x() - 0.3 == doctest::Approx(-(l.p.x() + 0.3)));
    CHECK(r.p.y() == doctest::Approx(l.p.y()));
    CHECK(r.p.z() == doctest::Approx(l.p.z()));
    // The palm faces world +y at zero; every pad but the thumb's faces the same way.
    CHECK(r_palm.M.UnitZ().y() == doctest::Approx(1.0));
    if (f < 4) {
      CHECK(r.M.UnitZ().y() == doctest::Approx(1.0));
      CHECK(l.M.UnitZ().y() == doctest::Approx(1.0));
    }
    // The backs face the other way.
    KDL::Frame back;
    REQUIRE(m.tool_pose_m(Side::right, back_frame(f), arm, hand, back));
    CHECK(dot(back.M.UnitZ(), r.M.UnitZ()) == doctest::Approx(-1.0));
  }
}

TEST_CASE("the YAML's mounting replaces the URDF's: a 10 mm shift moves every tool frame by 10 mm") {
  const std::string yaml = robot_files::read(robot_files::shipped("crease_robot.yaml"));
  const std::string urdf = robot_files::read(robot_files::shipped("crease_robot.urdf"));
  const std::string moved = robot_files::replace(yaml, "xyz_mm: [300, -300, 1000]", "xyz_mm: [310, -300, 950]");
  RobotModel a = shipped_model();
  RobotModel b = RobotModel::load(robot_files::write_robot(moved, "mount_shift.urdf", urdf));
  const auto arm = zero_arm();
  auto hand = zero_hand();
  hand[hand_index("THJ4")] = 0.5;
  for (int f = 0; f < kToolFrames; ++f) {
    KDL::Frame pa, pb;
    REQUIRE(a.tool_pose_m(Side::right, static_cast<ToolFrame>(f), arm, hand, pa));
    REQUIRE(b.tool_pose_m(Side::right, static_cast<ToolFrame>(f), arm, hand, pb));
    check_frame(pb, pa.p + KDL::Vector(0.010, 0, -0.050), pa.M, 1e-12);
    REQUIRE(a.tool_pose_m(Side::left, static_cast<ToolFrame>(f), arm, hand, pa));
    REQUIRE(b.tool_pose_m(Side::left, static_cast<ToolFrame>(f), arm, hand, pb));
    check_frame(pb, pa.p, pa.M, 1e-12);
  }
  CHECK(b.mount(Side::right).p.z() == doctest::Approx(0.95));
}

TEST_CASE("collision shapes: pads are their own links, fingertips are covered, friction per side") {
  const RobotModel m = shipped_model();
  const auto& p = m.params();
  CHECK(p.side(Side::right).cover == "rubber");
  CHECK(p.side(Side::left).cover == "fabric");
  CHECK(p.side(Side::right).cover_friction > p.paper_table_friction);  // it can drag the sheet
  CHECK(p.side(Side::left).cover_friction < p.paper_paper_friction);   // it slides over a layer
  for (int s = 0; s < kSides; ++s) {
    const SideParams& sp = p.sides[s];
    for (const char* finger : {"ff", "mf", "rf", "lf", "th"}) {
      for (const char* part : {"pad", "back"}) {
        const auto shapes = m.shapes_of(sp.prefix + finger + part);
        REQUIRE(shapes.size() == 1);
        CHECK(shapes[0].kind == ShapeKind::box);
        CHECK(shapes[0].surface == Surface::cover);
        CHECK(shapes[0].friction == sp.cover_friction);
        CHECK(shapes[0].half_extents_m[2] == doctest::Approx(0.001));
        CHECK(shapes[0].link_from_shape.p.z() == doctest::Approx(-0.001));  // under the surface
      }
      const auto tip = m.shapes_of(sp.prefix + finger + "distal");
      REQUIRE(tip.size() == 1);
      CHECK(tip[0].kind == ShapeKind::capsule);
      CHECK(tip[0].friction == sp.cover_friction);
      const auto middle = m.shapes_of(sp.prefix + finger + "middle");
      REQUIRE(middle.size() == 1);
      CHECK(middle[0].kind == ShapeKind::capsule);
      CHECK(middle[0].surface == Surface::shell);
      CHECK(middle[0].friction == sp.shell_friction);
    }
    const auto palm = m.shapes_of(sp.prefix + "palm");
    REQUIRE(palm.size() == 1);
    CHECK(palm[0].kind == ShapeKind::box);
    CHECK(m.shapes_of(sp.prefix + "forearm").size() == 2);
    for (int i = 2; i <= 6; ++i) CHECK(m.shapes_of(sp.prefix + "link" + std::to_string(i))[0].kind == ShapeKind::capsule);
  }
  // The distal capsule of the first finger: radius 8.5 mm, caps 12 mm apart.
  const auto ff = m.shapes_of("r_ffdistal");
  CHECK(ff[0].radius_m == doctest::Approx(0.0085));
  CHECK(ff[0].length_m == doctest::Approx(0.012));
}

TEST_CASE("a URDF without one of the hand's 20 joints, or with an unknown movable joint, is refused") {
  const std::string yaml = robot_files::read(robot_files::shipped("crease_robot.yaml"));
  const std::string urdf = robot_files::read(robot_files::shipped("crease_robot.urdf"));
  SUBCASE("a hand joint renamed") {
    const std::string bad = robot_files::replace(urdf, "name=\"l_THJ3\"", "name=\"l_THJ3b\"");
    const std::string path = robot_files::write_robot(yaml, "no_thj3.urdf", bad);
    CHECK_THROWS_WITH_AS(
        (void)RobotModel::load(path),
        doctest::Contains("no_thj3.urdf: joint 'l_THJ3': missing: one of the 20 hand joints"),
        crease::ConfigError);
  }
  SUBCASE("a distal joint that no longer follows J2") {
    const std::string bad = robot_files::replace(urdf, "    <mimic joint=\"r_MFJ2\" multiplier=\"1\" offset=\"0\"/>\n", "");
    const std::string path = robot_files::write_robot(yaml, "no_mimic.urdf", bad);
    const int line = robot_files::line_of(bad, "<joint name=\"r_MFJ1\"");
    CHECK_THROWS_WITH_AS(
        (void)RobotModel::load(path),
        doctest::Contains(
            ("no_mimic.urdf:" + std::to_string(line) + ": joint 'r_MFJ1': neither").c_str()),
        crease::ConfigError);
  }
  SUBCASE("a tool frame missing") {
    std::string bad = robot_files::replace(urdf, "<child link=\"l_palmfront\"/>", "<child link=\"l_palmfrnt\"/>");
    bad = robot_files::replace(bad, "<link name=\"l_palmfront\"/>", "<link name=\"l_palmfrnt\"/>");
    const std::string path = robot_files::write_robot(yaml, "no_palm.urdf", bad);
    CHECK_THROWS_WITH_AS((void)RobotModel::load(path),
                         doctest::Contains("link 'l_palmfront': missing"), crease::ConfigError);
  }
  SUBCASE("a URDF error surfaces through load with its file and line") {
    const std::string bad = robot_files::replace(urdf, "<parent link=\"r_link1\"/>", "<parent link=\"r_lnk1\"/>");
    const std::string path = robot_files::write_robot(yaml, "bad_parent.urdf", bad);
    const int line = robot_files::line_of(bad, "r_lnk1");
    CHECK_THROWS_WITH_AS(
        (void)RobotModel::load(path),
        doctest::Contains(
            ("bad_parent.urdf:" + std::to_string(line) + ": joint 'r_S2' <parent>").c_str()),
        crease::ConfigError);
  }
}

TEST_CASE("a bad key in the robot's YAML is refused with the file, line and key") {
  const std::string yaml = robot_files::read(robot_files::shipped("crease_robot.yaml"));
  const std::string urdf = robot_files::read(robot_files::shipped("crease_robot.urdf"));
  const std::string bad = robot_files::replace(yaml, "noise_kpa: 1.0", "noise: 1.0");
  const std::string path = robot_files::write_robot(bad, "bad_key.urdf", urdf);
  const int line = robot_files::line_of(bad, "noise: 1.0");
  CHECK_THROWS_WITH_AS((void)RobotModel::load(path),
                       doctest::Contains(("bad_key.urdf.yaml:" + std::to_string(line) +
                                          ":7: sides.right.tactile.noise: unknown key 'noise'")
                                             .c_str()),
                       crease::ConfigError);
}

TEST_CASE("the forward kinematics of every tool frame allocates nothing") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  RobotModel m = shipped_model();
  auto arm = zero_arm();
  auto hand = zero_hand();
  KDL::Frame out;
  double sum = 0;
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    for (int k = 0; k < 100; ++k) {
      arm[k % kArmJoints] += 0.01;
      hand[k % kHandJoints] += 0.001;
      for (int s = 0; s < kSides; ++s) {
        for (int f = 0; f < kToolFrames; ++f) {
          CHECK(m.tool_pose_m(static_cast<Side>(s), static_cast<ToolFrame>(f), arm, hand, out));
          sum += out.p.z();
        }
      }
    }
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(std::isfinite(sum));
  // The guard sees this library's allocations: building a chain (what load does) counts.
  {
    crease::rt::ScopedRtMark rt;
    const ToolChain c = m.make_chain(Side::left, "l_thpad");
    CHECK(c.chain().getNrOfJoints() == 7 + 2 + 5);
  }
  CHECK(crease::rt::rt_allocation_count() > before);
}
