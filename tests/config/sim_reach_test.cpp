// Can the simulated robot reach the sheet where config/sim.yaml lays it? The folding sequence's
// first goals (config/folds/half.yaml and diagonal.yaml: the right hand's approach and contact,
// the left hand's grasp) in arm_motion's sheet frame of the world's sheet at its nominal pose
// and at the randomisation's extremes (sim_world: +-30 mm, +-15 deg), solved with the arm's IK
// (robot_model's ArmIk, the URDF's joint limits) from the rest posture and its restarts, as
// given (which must be reached) and turned about the sheet's normal (72 turns, 5 deg apart:
// how many are). Prints, per goal, the shoulder's distance to the tool and the IK's residual.
// Failing variant: the arms mounted as before (1.3 m over the table, 450 mm behind the sheet's
// centre): the approach is out of reach at every turn. And at the shift's contact, the open
// hand's shells (plastic) clear of the sheet by more than the descent's depth over its lowest
// fingertip cover; failing variant: the pad flat on the sheet. And the half fold's bend from the
// pinch through its via points as arm_motion checks the path; failing variant: the via points'
// orientations without the pinch's own turn.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "plugins/fold_sequence/fold_spec.h"
#include "plugins/robot_model/arm_ik.h"
#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/sim_world.h"
#include "plugins/sim_world/world_config.h"

using namespace crease;
using robot::ArmIk;
using robot::Side;
using robot::ToolFrame;

namespace {

const std::string kConfig = std::string(CREASE_SOURCE_DIR) + "/config/";

// The world's table height (sim.yaml's world params; sim_world's default 0).
double table_height_mm() {
  const YAML::Node root = YAML::LoadFile(kConfig + "sim.yaml");
  for (const auto& p : root["plugins"])
    if (p["library"].as<std::string>() == "sim_world" && p["params"]["table_height_mm"])
      return p["params"]["table_height_mm"].as<double>();
  return 0.0;
}

// arm_motion's sheet frame of a sheet lying flat: origin node (0, 0) at CORNER (world mm), x along
// u, z = u x v into the table; the A4 sheet's u along +x and v along -y turned by YAW about z.
KDL::Frame sheet_frame(double x_mm, double y_mm, double z_mm, double yaw_rad) {
  return KDL::Frame(KDL::Rotation::RotZ(yaw_rad) * KDL::Rotation::RotX(std::numbers::pi),
                    KDL::Vector(x_mm, y_mm, z_mm) / 1000.0);
}

struct Reach {
  bool reached = false;     // the goal's own orientation converged within the limits
  bool any_turn = false;    // some turn did
  double best_mm = 1e9;     // the smallest residual over the turns
  int turns_reached = 0;    // of 72
  double shoulder_tool_mm = 0;
};

// The shoulder (S2's axis) in the world: 0.317 m down the arm's base from its mount.
KDL::Vector shoulder(const robot::RobotModel& m, Side s) { return m.mount(s) * KDL::Vector(0, 0, 0.317); }

Reach reach(const robot::RobotModel& m, Side side, ToolFrame tool, const KDL::Frame& goal) {
  ArmIk ik(m, side);
  const ArmIk::Joints rest = ik.options().rest_rad;
  const std::array<double, robot::kHandJoints> hand{};  // the sequence's open hand
  REQUIRE(ik.set_tool(tool, rest, hand));
  Reach r;
  r.shoulder_tool_mm = 1000.0 * (goal.p - shoulder(m, side)).Norm();
  for (int k = 0; k < 72; ++k) {
    const KDL::Frame g(goal.M * KDL::Rotation::RotZ(k * std::numbers::pi / 36.0), goal.p);
    ArmIk::Joints q{};
    const ArmIk::Result res = ik.solve(g, rest, q);
    r.best_mm = std::min(r.best_mm, 1000.0 * res.error_m);
    if (res.converged) {
      r.reached = r.reached || k == 0;
      r.any_turn = true;
      ++r.turns_reached;
    }
  }
  return r;
}

KDL::Frame sheet_goal(const KDL::Frame& sheet, const double p_mm[3], const double q[4]) {
  return sheet * KDL::Frame(KDL::Rotation::Quaternion(q[0], q[1], q[2], q[3]),
                            KDL::Vector(p_mm[0], p_mm[1], p_mm[2]) / 1000.0);
}

// Every first goal of FOLD at every extreme of the sheet's pose; prints the figures.
int unreachable_goals(const robot::RobotModel& m, const std::string& fold, const std::string& tag) {
  const fold::FoldSpec f = fold::load_fold_file(kConfig + "folds/" + fold + ".yaml");
  const double z = table_height_mm();
  int missed = 0;
  for (double dx : {0.0, -30.0, 30.0})
    for (double dy : {0.0, -30.0, 30.0})
      for (double yaw_deg : {0.0, -15.0, 15.0}) {
        // The sheet turns about its centre (sim_world's randomise): the corner moves with it.
        const double yaw = yaw_deg * std::numbers::pi / 180.0;
        const KDL::Vector c(dx, dy, 0), corner0(-105, 148.5, 0);
        const KDL::Vector corner = c + KDL::Rotation::RotZ(yaw) * corner0;
        const KDL::Frame sheet = sheet_frame(corner.x(), corner.y(), z, yaw);
        const double approach[3] = {f.shift.at_mm[0], f.shift.at_mm[1], -f.shift.approach_height_mm};
        const double contact[3] = {f.shift.at_mm[0], f.shift.at_mm[1], 0.0};
        struct Goal {
          const char* what;
          Side side;
          std::uint8_t tool;
          const double* p;
          const double* q;
        } goals[] = {
            {"shift approach", Side::right, f.shift.tool, approach, f.shift.orientation},
            {"shift contact", Side::right, f.shift.tool, contact, f.shift.orientation},
            {"grasp above", Side::left, f.grasp_tool, f.grasp_above_mm, f.grasp_orientation},
            {"grasp at", Side::left, f.grasp_tool, f.grasp_at_mm, f.grasp_orientation},
        };
        for (const Goal& g : goals) {
          const KDL::Frame goal = sheet_goal(sheet, g.p, g.q);
          const Reach r = reach(m, g.side, static_cast<ToolFrame>(g.tool), goal);
          if (!r.reached) ++missed;
          if (dx == 0 && dy == 0 && yaw_deg == 0)
            MESSAGE(tag << " " << fold << " " << std::string(g.what) << ": tool at (" << 1000 * goal.p.x() << ", "
                        << 1000 * goal.p.y() << ", " << 1000 * goal.p.z() << ") mm, " << r.shoulder_tool_mm
                        << " mm from the shoulder; as given " << std::string(r.reached ? "reached" : "not reached") << ", " << r.turns_reached << " of 72 turns reached, best residual "
                        << r.best_mm << " mm");
        }
      }
  return missed;
}

// The shipped robot file with its mounts edited (the URDF beside it, copied).
robot::RobotModel mounted(double z_mm, double y_mm) {
  std::ifstream in(kConfig + "robot/crease_robot.yaml");
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  for (const char* x : {"[300, ", "[-300, "}) {
    const std::string from = std::string("mount: {xyz_mm: ") + x;
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    const auto end = text.find(']', at);
    text.replace(at, end - at + 1,
                 from + std::to_string(static_cast<int>(y_mm)) + ", " + std::to_string(static_cast<int>(z_mm)) + "]");
  }
  const auto dir = std::filesystem::temp_directory_path() / ("crease_sim_reach_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kConfig + "robot/crease_robot.urdf", dir / "crease_robot.urdf",
                             std::filesystem::copy_options::overwrite_existing);
  std::ofstream(dir / "crease_robot.yaml") << text;
  return robot::RobotModel::load((dir / "crease_robot.yaml").string());
}

}  // namespace

TEST_CASE("the arms reach the sequence's first goals on the sheet where sim.yaml lays it, at every pose the world draws") {
  const robot::RobotModel shipped = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  MESSAGE("right mount at (" << 1000 * shipped.mount(Side::right).p.x() << ", " << 1000 * shipped.mount(Side::right).p.y()
                             << ", " << 1000 * shipped.mount(Side::right).p.z() << ") mm, table at " << table_height_mm()
                             << " mm");
  CHECK(unreachable_goals(shipped, "half", "shipped") == 0);
  CHECK(unreachable_goals(shipped, "diagonal", "shipped") == 0);

  // Failing variant: the mounts as they were.
  const robot::RobotModel before = mounted(1300, -450);
  CHECK(unreachable_goals(before, "half", "1.3 m mounts") > 0);
}

TEST_CASE("the arms' parked pose (sim_world's default): each index pad 300 mm over the table, facing down, turned as its first goal, beside the sheet, clear of the limits") {
  robot::RobotModel m = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  const std::array<double, robot::kHandJoints> hand{};
  for (Side s : {Side::right, Side::left}) {
    const int i = s == Side::right ? 0 : 1;
    ArmIk::Joints q{};
    for (int j = 0; j < robot::kArmJoints; ++j) q[j] = world::kParkedArmDeg[i][j] * std::numbers::pi / 180.0;
    KDL::Frame pad;
    REQUIRE(m.tool_pose_m(s, ToolFrame::ff_pad, q, hand, pad));
    CHECK(std::fabs(1000 * pad.p.x() - (i == 0 ? 230 : -230)) < 1.0);
    CHECK(std::fabs(1000 * pad.p.y() + 230) < 1.0);
    CHECK(std::fabs(1000 * pad.p.z() - (table_height_mm() + 300)) < 1.0);
    CHECK(pad.M.UnitZ().z() < -0.999);  // the pad's outward normal down
    const double yaw_deg = std::atan2(pad.M.UnitX().y(), pad.M.UnitX().x()) * 180.0 / std::numbers::pi;
    CHECK(std::fabs(yaw_deg - (i == 0 ? 90.0 : 60.0)) < 0.5);  // turned as the first goal (half.yaml)
    const ArmIk ik(m, s);
    for (int j = 0; j < robot::kArmJoints; ++j) {
      CHECK(q[j] > ik.lower()[j] + 0.43);  // 25 deg
      CHECK(q[j] < ik.upper()[j] - 0.43);
    }
  }
}



// The open hand over the sheet at the shift's contact (the sequence's first touch): how far
// above its lowest fingertip cover (rubber) its lowest shell (plastic: palm, wrist, forearm,
// phalanges, thumb) is, in mm, with the tool at ORIENTATION (sheet frame, the fold file's
// convention), on the nominal sheet. The hand's shapes where the world puts them
// (sim_world's shapes at the arm's IK solution; the heights do not depend on the sheet's yaw).
struct Clearance {
  double shell_over_cover_mm = 0;
  std::string lowest_shell;
};
Clearance contact_clearance(const robot::RobotModel& m, const fold::FoldSpec& f, const double orientation[4]) {
  const KDL::Frame sheet = sheet_frame(-105, 148.5, table_height_mm(), 0);
  const double contact[3] = {f.shift.at_mm[0], f.shift.at_mm[1], 0.0};
  ArmIk ik(m, Side::right);
  const std::array<double, robot::kHandJoints> open{};  // the sequence's open hand
  REQUIRE(ik.set_tool(static_cast<ToolFrame>(f.shift.tool), ik.options().rest_rad, open));
  ArmIk::Joints q{};
  REQUIRE(ik.solve(sheet_goal(sheet, contact, orientation), ik.options().rest_rad, q).converged);
  world::WorldParams p;
  p.table_height_mm = table_height_mm();
  p.hand_contacts = false;  // where the arm puts the hand, nothing deflecting it
  p.randomise = false;
  for (int j = 0; j < robot::kArmJoints; ++j) p.initial_arm_rad[0][j] = q[j];
  world::World w(m, p);
  w.step_rt();
  const double cover_k = world::WorldParams{}.contact_stiffness_n_per_mm3.at(m.params().side(Side::right).cover);
  double cover = 1e9, shell = 1e9;
  Clearance c;
  for (const world::WorldShape& s : w.shapes()) {
    if (s.side != static_cast<int>(Side::right)) continue;
    const double z = world::lowest_point(s.geom, s.pose1).z;
    if (s.stiffness_n_per_mm3 == cover_k) {
      cover = std::min(cover, z);
    } else if (s.role != world::ShapeRole::arm && z < shell) {
      shell = z;
      c.lowest_shell = w.kinematics(Side::right).link_name(s.link);
    }
  }
  c.shell_over_cover_mm = shell - cover;
  return c;
}

TEST_CASE("at the shift's contact the open hand touches the sheet with its fingertip covers only, its shells clear by more than the descent's depth") {
  const robot::RobotModel m = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  for (const char* name : {"half", "diagonal"}) {
    const fold::FoldSpec f = fold::load_fold_file(kConfig + "folds/" + name + ".yaml");
    // As shipped: the pad pitched 20 deg (the fingers down, the wrist up).
    const Clearance shipped = contact_clearance(m, f, f.shift.orientation);
    MESSAGE(std::string(name) << ": the lowest shell (" << shipped.lowest_shell << ") " << shipped.shell_over_cover_mm
                 << " mm over the lowest fingertip cover");
    CHECK(shipped.shell_over_cover_mm > f.shift.contact_depth_mm);
    // Failing variant: the pad flat on the sheet (the orientation before, turned about the
    // normal only): the forearm's flange shell, the thumb, wrist and palm hang below the pads.
    const double flat[4] = {0, 0, -0.70711, 0.70711};
    const Clearance before = contact_clearance(m, f, flat);
    MESSAGE(std::string(name) << ", the pad flat: the lowest shell (" << before.lowest_shell << ") " << before.shell_over_cover_mm
                 << " mm over the lowest fingertip cover");
    CHECK(before.shell_over_cover_mm < 0.0);
  }
}

namespace {

// The bend of FOLD as arm_motion checks it: the left tool at the grasp (the open hand, from the
// rest posture), the index curled by pinch_rad (the pinched pad), then each via point in turn,
// the path in steps of at most 5 mm and 0.05 rad tracked from the last solution (3 tries), each
// joint within 0.9 of its velocity limit at the fold's speeds. The sheet as the shift leaves it
// (its corner at corner_target), turned YAW_DEG. UNTURNED: each via's orientation with the
// pinch's own turn taken out (the sheet's turn alone, applied to the pad as before the pinch).
// Returns how many via points are not reached (from the first that fails on), and prints it.
int bend_failures(const robot::RobotModel& m, const fold::FoldSpec& f, double yaw_deg, bool unturned) {
  const double yaw = yaw_deg * std::numbers::pi / 180.0;
  const KDL::Vector cv = KDL::Rotation::RotZ(yaw) * KDL::Vector(f.corner_mm[0], -f.corner_mm[1], 0) / 1000.0;
  const KDL::Vector origin = KDL::Vector(f.corner_target_mm[0], f.corner_target_mm[1], 0) / 1000.0 - cv;
  const KDL::Frame sheet = sheet_frame(1000 * origin.x(), 1000 * origin.y(), table_height_mm(), yaw);
  ArmIk ik(m, Side::left);
  std::array<double, robot::kHandJoints> hand{};
  REQUIRE(ik.set_tool(static_cast<ToolFrame>(f.grasp_tool), ik.options().rest_rad, hand));
  ArmIk::Joints q{};
  REQUIRE(ik.solve(sheet_goal(sheet, f.grasp_at_mm, f.grasp_orientation), ik.options().rest_rad, q).converged);
  for (int j = 0; j < robot::kHandJoints; ++j) hand[j] = f.pinch_rad[j];
  REQUIRE(ik.set_tool(static_cast<ToolFrame>(f.grasp_tool), q, hand));
  KDL::Frame from = ik.tool_pose(q);
  const KDL::Rotation pinched = sheet.M.Inverse() * from.M;  // the pinched pad in the sheet frame
  int failures = 0;
  bool printed = false;
  for (int k = 0; k < f.via_count; ++k) {
    const double* vq = f.via_orientation[k];
    KDL::Rotation r = KDL::Rotation::Quaternion(vq[0], vq[1], vq[2], vq[3]);
    if (unturned) r = r * pinched.Inverse();
    const KDL::Frame to = sheet * KDL::Frame(r, KDL::Vector(f.via_mm[k][0], f.via_mm[k][1], f.via_mm[k][2]) / 1000.0);
    const double len = (to.p - from.p).Norm();
    KDL::Vector axis;
    const double ang = (from.M.Inverse() * to.M).GetRotAngle(axis);
    const int steps = std::max(1, static_cast<int>(std::ceil(std::max(len / 0.005, ang / 0.05))));
    const double dt = std::max(len / steps / (f.fold.speed_mm_s * 1e-3), ang / steps / f.fold.angular_speed_rad_s);
    bool ok = true;
    for (int s = 1; s <= steps && ok; ++s) {
      const double a = static_cast<double>(s) / steps;
      const KDL::Frame g(from.M * KDL::Rotation::Rot(axis, a * ang), from.p + a * (to.p - from.p));
      const ArmIk::Joints before = q;
      ArmIk::Result res;
      for (int t = 0; t < 3 && !res.converged; ++t) res = ik.track(g, q);
      ok = res.converged;
      for (int j = 0; j < robot::kArmJoints && ok; ++j) ok = std::fabs(q[j] - before[j]) / dt <= 0.9 * ik.velocity_limit()[j];
      if (!ok && !printed) {
        printed = true;
        const std::string what = f.name + (unturned ? " (unturned)" : "");
        MESSAGE(what << " yaw " << yaw_deg << ": via " << k << " fails at " << a << " of its segment (IK residual "
                     << 1000 * res.error_m << " mm)");
      }
    }
    if (!ok) return failures + (f.via_count - k);  // this one and the rest: the arm is stuck here
    from = to;
  }
  return failures;
}

}  // namespace

TEST_CASE("the bend's path from the pinch reaches every via point of the half fold within the limits and speeds, at every turn of the sheet") {
  const robot::RobotModel m = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  const fold::FoldSpec half = fold::load_fold_file(kConfig + "folds/half.yaml");
  for (double yaw_deg : {0.0, -15.0, 15.0}) {
    CAPTURE(yaw_deg);
    CHECK(bend_failures(m, half, yaw_deg, false) == 0);
  }
  // The diagonal fold's bend is not there yet: its third via point is out of the path's reach.
  const fold::FoldSpec diagonal = fold::load_fold_file(kConfig + "folds/diagonal.yaml");
  MESSAGE("diagonal: " << bend_failures(m, diagonal, 0.0, false) << " of " << diagonal.via_count << " via points not reached");
  // Failing variant: the via points as the sheet's turn alone (the pad before the pinch).
  int unturned = 0;
  for (double yaw_deg : {0.0, -15.0, 15.0}) unturned += bend_failures(m, half, yaw_deg, true);
  CHECK(unturned > 0);
}
