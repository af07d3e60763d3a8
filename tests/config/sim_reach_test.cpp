// Can the simulated robot reach the sheet where config/sim.yaml lays it? The folding sequence's
// first goals (config/folds/half.yaml and diagonal.yaml: the shifting hand's approach and contact,
// the fixing hand's, the pinching hand's grasp: above the edge, round it, at the pinch) in
// arm_motion's sheet frame of the world's sheet (sim.yaml's corner, turn and table) at its nominal
// pose and at the randomisation's extremes (sim_world: +-30 mm, +-15 deg), solved with the arm's IK
// (robot_model's ArmIk, the URDF's joint limits) from the rest posture and its restarts, as given
// (which must be reached) and turned about the sheet's normal (72 turns, 5 deg apart: how many
// are). Prints, per goal, the shoulder's distance to the tool and the IK's residual. Failing
// variant: the arms mounted as before (1.3 m over the table, 450 mm behind the sheet's centre).
// Then the pinching arm's grasp from the world's parked pose, as arm_motion checks a path (failing
// variant: the straight turn from the parked pose, without above_via). At the shift's contact, the
// open hand's shells (plastic) clear of the sheet by more than the descent's depth over its lowest
// fingertip cover; failing variant: the pad flat on the sheet. And the half fold's bend from the
// pinch through its via points to 120 deg as arm_motion checks a path; failing variant: the via
// points' orientations without the pinch's own turn.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

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
using Hand = std::array<double, robot::kHandJoints>;

// Where sim.yaml's world lays the flat sheet: its corner (0, 0) (mm), its turn about z (rad),
// the table's height (mm); sim_world's defaults where sim.yaml is silent.
struct Layout {
  double x_mm = -105, y_mm = 148.5, turn_rad = 0, table_mm = 0;
};
Layout layout() {
  const YAML::Node root = YAML::LoadFile(kConfig + "sim.yaml");
  Layout l;
  for (const auto& p : root["plugins"]) {
    if (p["library"].as<std::string>() != "sim_world") continue;
    const YAML::Node w = p["params"];
    if (w["origin_x_mm"]) l.x_mm = w["origin_x_mm"].as<double>();
    if (w["origin_y_mm"]) l.y_mm = w["origin_y_mm"].as<double>();
    if (w["sheet_turn_deg"]) l.turn_rad = w["sheet_turn_deg"].as<double>() * std::numbers::pi / 180.0;
    if (w["table_height_mm"]) l.table_mm = w["table_height_mm"].as<double>();
  }
  return l;
}

// arm_motion's sheet frame of the flat sheet laid as L says, then turned by YAW about its centre
// and shifted by (DX, DY) mm (sim_world's randomise): origin node (0, 0), x along u, z = u x v
// into the table.
KDL::Frame sheet_frame(const Layout& l, double dx, double dy, double yaw) {
  const KDL::Rotation r0 = KDL::Rotation::RotZ(l.turn_rad) * KDL::Rotation::RotX(std::numbers::pi);
  const KDL::Vector half(0.105, 0.1485, 0);
  const KDL::Vector centre = KDL::Vector(l.x_mm, l.y_mm, l.table_mm) / 1000.0 + r0 * half + KDL::Vector(dx, dy, 0) / 1000.0;
  const KDL::Rotation r = KDL::Rotation::RotZ(yaw) * r0;
  return KDL::Frame(r, centre - r * half);
}

// The sheet frame once the shift has put the fold's corner_mm on corner_target_mm, turned YAW.
KDL::Frame shifted_sheet(const Layout& l, const fold::FoldSpec& f, double yaw) {
  const KDL::Frame s = sheet_frame(l, 0, 0, yaw);
  const KDL::Vector corner = s.M * KDL::Vector(f.corner_mm[0], f.corner_mm[1], 0) / 1000.0;
  const KDL::Vector target = KDL::Vector(f.corner_target_mm[0], f.corner_target_mm[1], l.table_mm) / 1000.0;
  return KDL::Frame(s.M, target - corner);
}

Side fixing(const fold::FoldSpec& f) { return f.pinching_side == 0 ? Side::left : Side::right; }
Side pinching(const fold::FoldSpec& f) { return f.pinching_side == 0 ? Side::right : Side::left; }
// The hand that shifts the sheet (shift.hand): the fixing one, or the pinching one (half.yaml).
Side shifting(const fold::FoldSpec& f) {
  return f.shift_role == 1 ? pinching(f) : fixing(f);
}
Hand posture(const float* rad) {
  Hand h{};
  for (int j = 0; j < robot::kHandJoints; ++j) h[j] = rad[j];
  return h;
}

struct Reach {
  bool reached = false;     // the goal's own orientation converged within the limits
  double best_mm = 1e9;     // the smallest residual over the turns
  int turns_reached = 0;    // of 72
  double shoulder_tool_mm = 0;
};

// The shoulder (S2's axis) in the world: 0.317 m down the arm's base from its mount.
KDL::Vector shoulder(const robot::RobotModel& m, Side s) { return m.mount(s) * KDL::Vector(0, 0, 0.317); }

Reach reach(const robot::RobotModel& m, Side side, ToolFrame tool, const Hand& hand, const KDL::Frame& goal) {
  ArmIk ik(m, side);
  const ArmIk::Joints rest = ik.options().rest_rad;
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
  const Layout l = layout();
  int missed = 0;
  for (double dx : {0.0, -30.0, 30.0})
    for (double dy : {0.0, -30.0, 30.0})
      for (double yaw_deg : {0.0, -15.0, 15.0}) {
        const KDL::Frame sheet = sheet_frame(l, dx, dy, yaw_deg * std::numbers::pi / 180.0);
        const double approach[3] = {f.shift.at_mm[0], f.shift.at_mm[1], -f.shift.approach_height_mm};
        const double contact[3] = {f.shift.at_mm[0], f.shift.at_mm[1], 0.0};
        const double fix_approach[3] = {f.fixate.at_mm[0], f.fixate.at_mm[1],
                                        -f.fixate.approach_height_mm};
        const double fix_contact[3] = {f.fixate.at_mm[0], f.fixate.at_mm[1], 0.0};
        struct Goal {
          std::string what;
          Side side;
          std::uint8_t tool;
          const double* p;
          const double* q;
          Hand hand;
        };
        std::vector<Goal> goals = {
            {"shift approach", shifting(f), f.shift.tool, approach, f.shift.orientation,
             posture(f.open_rad)},
            {"shift contact", shifting(f), f.shift.tool, contact, f.shift.orientation,
             posture(f.open_rad)},
            {"fixate approach", fixing(f), f.fixate.tool, fix_approach, f.fixate.orientation,
             posture(f.open_rad)},
            {"fixate contact", fixing(f), f.fixate.tool, fix_contact, f.fixate.orientation,
             posture(f.open_rad)},
            {"grasp above", pinching(f), f.grasp_tool, f.grasp_above_mm, f.grasp_orientation,
             posture(f.prepinch_rad)},
        };
        for (int k = 0; k < f.grasp_path_count; ++k)
          goals.push_back({"grasp path " + std::to_string(k), pinching(f), f.grasp_tool, f.grasp_path_mm[k],
                           f.grasp_orientation, posture(f.prepinch_rad)});
        goals.push_back({"grasp at", pinching(f), f.grasp_tool, f.grasp_at_mm, f.grasp_orientation, posture(f.prepinch_rad)});
        for (const Goal& g : goals) {
          const KDL::Frame goal = sheet_goal(sheet, g.p, g.q);
          const Reach r = reach(m, g.side, static_cast<ToolFrame>(g.tool), g.hand, goal);
          if (!r.reached) ++missed;
          if (dx == 0 && dy == 0 && yaw_deg == 0)
            MESSAGE(tag << " " << fold << " " << g.what << ": tool at (" << 1000 * goal.p.x() << ", " << 1000 * goal.p.y()
                        << ", " << 1000 * goal.p.z() << ") mm, " << r.shoulder_tool_mm << " mm from the shoulder; as given "
                        << std::string(r.reached ? "reached" : "not reached") << ", " << r.turns_reached
                        << " of 72 turns reached, best residual " << r.best_mm << " mm");
        }
      }
  return missed;
}

// A path from FROM through POINTS as arm_motion checks it: in steps of at most 5 mm and 0.05 rad
// tracked from the last solution Q (3 tries), each joint within 0.9 of its velocity limit at the
// limits LIM. Returns how many points are not reached (from the first that fails on: the arm is
// stuck there), and prints where it failed; Q ends at the last point reached.
int path_failures(ArmIk& ik, ArmIk::Joints& q, KDL::Frame from, const std::vector<KDL::Frame>& points,
                  const fold::MotionLimits& lim, const std::string& what) {
  const int n = static_cast<int>(points.size());
  for (int k = 0; k < n; ++k) {
    const KDL::Frame& to = points[static_cast<std::size_t>(k)];
    const double len = (to.p - from.p).Norm();
    KDL::Vector axis;
    const double ang = (from.M.Inverse() * to.M).GetRotAngle(axis);
    const int steps = std::max(1, static_cast<int>(std::ceil(std::max(len / 0.005, ang / 0.05))));
    const double dt = std::max(len / steps / (lim.speed_mm_s * 1e-3), ang / steps / lim.angular_speed_rad_s);
    for (int s = 1; s <= steps; ++s) {
      const double a = static_cast<double>(s) / steps;
      const KDL::Frame g(from.M * KDL::Rotation::Rot(axis, a * ang), from.p + a * (to.p - from.p));
      const ArmIk::Joints before = q;
      ArmIk::Result res;
      for (int t = 0; t < 3 && !res.converged; ++t) res = ik.track(g, q);
      bool ok = res.converged;
      for (int j = 0; j < robot::kArmJoints && ok; ++j) ok = std::fabs(q[j] - before[j]) / dt <= 0.9 * ik.velocity_limit()[j];
      if (!ok) {
        MESSAGE(what << ": point " << k << " fails at " << a << " of its segment (IK residual " << 1000 * res.error_m
                     << " mm)");
        q = before;
        return n - k;
      }
    }
    from = to;
  }
  return 0;
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

ArmIk::Joints parked(Side s) {
  ArmIk::Joints q{};
  const int i = s == Side::right ? 0 : 1;
  for (int j = 0; j < robot::kArmJoints; ++j) q[j] = world::kParkedArmDeg[i][j] * std::numbers::pi / 180.0;
  return q;
}

}  // namespace

TEST_CASE("the arms reach the sequence's first goals on the sheet where sim.yaml lays it, at every pose the world draws") {
  const robot::RobotModel shipped = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  MESSAGE("right mount at (" << 1000 * shipped.mount(Side::right).p.x() << ", " << 1000 * shipped.mount(Side::right).p.y()
                             << ", " << 1000 * shipped.mount(Side::right).p.z() << ") mm, table at " << layout().table_mm
                             << " mm");
  CHECK(unreachable_goals(shipped, "half", "shipped") == 0);
  // The diagonal fold's numbers are for the sheet as it lay before (unturned): not yet redone.
  MESSAGE("diagonal: " << unreachable_goals(shipped, "diagonal", "shipped") << " first goals out of reach");

  // Failing variant: the mounts as they were.
  const robot::RobotModel before = mounted(1300, -450);
  CHECK(unreachable_goals(before, "half", "1.3 m mounts") > 0);
}

TEST_CASE("the arms' parked pose (sim_world's default): each index pad 300 mm over the table, facing down, beside the sheet, clear of the limits") {
  robot::RobotModel m = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  const Hand hand{};
  for (Side s : {Side::right, Side::left}) {
    const int i = s == Side::right ? 0 : 1;
    const ArmIk::Joints q = parked(s);
    KDL::Frame pad;
    REQUIRE(m.tool_pose_m(s, ToolFrame::ff_pad, q, hand, pad));
    CHECK(std::fabs(1000 * pad.p.x() - (i == 0 ? 230 : -230)) < 1.0);
    CHECK(std::fabs(1000 * pad.p.y() + 230) < 1.0);
    CHECK(std::fabs(1000 * pad.p.z() - (layout().table_mm + 300)) < 1.0);
    CHECK(pad.M.UnitZ().z() < -0.999);  // the pad's outward normal down
    const ArmIk ik(m, s);
    for (int j = 0; j < robot::kArmJoints; ++j) {
      CHECK(q[j] > ik.lower()[j] + 0.43);  // 25 deg
      CHECK(q[j] < ik.upper()[j] - 0.43);
    }
  }
}

namespace {

// The pinching hand, shaped, from its parked pose (Q, set here and moved) through above_via to
// above the edge (approach limits), then round the overhang to the pinch (contact limits), on
// SHEET. VIA false: straight from the parked pose to above the edge. TURNED_FROM: above_via as a
// point of that sheet frame, turning with the sheet (else the world pose half.yaml gives).
// Returns how many points are not reached.
int grasp_failures(ArmIk& ik, ArmIk::Joints& q, const fold::FoldSpec& f, const KDL::Frame& sheet,
                   bool via = true, const KDL::Frame* turned_from = nullptr) {
  q = parked(pinching(f));
  REQUIRE(ik.set_tool(static_cast<ToolFrame>(f.grasp_tool), q, posture(f.prepinch_rad)));
  std::vector<KDL::Frame> to_above;
  for (int k = 0; k < f.grasp_above_via_count && via; ++k) {
    const double* p = f.grasp_above_via_mm[k];
    const double* r = f.grasp_above_via_orientation[k];
    REQUIRE(f.grasp_above_via_world[k]);
    const KDL::Frame world(KDL::Rotation::Quaternion(r[0], r[1], r[2], r[3]),
                           KDL::Vector(p[0], p[1], p[2]) / 1000.0);
    to_above.push_back(turned_from != nullptr ? sheet * (turned_from->Inverse() * world) : world);
  }
  const KDL::Frame above = sheet_goal(sheet, f.grasp_above_mm, f.grasp_orientation);
  to_above.push_back(above);
  const int missed = path_failures(ik, q, ik.tool_pose(q), to_above, f.approach, "grasp above");
  if (missed > 0) return missed + f.grasp_path_count + 1;
  std::vector<KDL::Frame> path;
  for (int k = 0; k < f.grasp_path_count; ++k)
    path.push_back(sheet_goal(sheet, f.grasp_path_mm[k], f.grasp_orientation));
  path.push_back(sheet_goal(sheet, f.grasp_at_mm, f.grasp_orientation));
  return path_failures(ik, q, above, path, f.contact, "grasp reach");
}

}  // namespace

TEST_CASE(
    "from the parked pose, the pinching arm's grasp of the half fold passes arm_motion's path "
    "check, at every yaw the world draws") {
  const robot::RobotModel m = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  const fold::FoldSpec f = fold::load_fold_file(kConfig + "folds/half.yaml");
  const Layout l = layout();
  // The pinching hand, shaped: parked, through above_via to above the edge (approach limits),
  // round the overhang to the pinch (contact limits), the sheet where the shift puts it.
  // VIA false: straight from the parked pose to above the edge.
  // Every yaw the world draws (+-15 deg). above_via is a world pose (half.yaml, `frame: world`);
  // TURNED: as a sheet point, turning with the sheet (at -15 deg out of reach: a trial, seed 14,
  // -14.6 deg, unreachable at once).
  const KDL::Frame nominal = shifted_sheet(l, f, 0);
  KDL::Frame sheet = nominal;
  auto grasp = [&](bool via, bool turned = false) {
    ArmIk ik(m, pinching(f));
    ArmIk::Joints q{};
    return grasp_failures(ik, q, f, sheet, via, turned ? &nominal : nullptr);
  };
  CHECK(grasp(true) == 0);
  CHECK(grasp(false) > 0);  // failing variant: the straight turn
  for (const double yaw_deg : {-15.0, -10.0, -5.0, 5.0, 10.0, 15.0}) {
    CAPTURE(yaw_deg);
    sheet = shifted_sheet(l, f, yaw_deg * std::numbers::pi / 180.0);
    CHECK(grasp(true) == 0);
  }
  sheet = shifted_sheet(l, f, -15.0 * std::numbers::pi / 180.0);
  CHECK(grasp(true, true) > 0);  // failing variant: above_via turned with the sheet
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
Clearance contact_clearance(const robot::RobotModel& m, Side side, const fold::ContactStep& step,
                            const double orientation[4]) {
  const Layout l = layout();
  const KDL::Frame sheet = sheet_frame(l, 0, 0, 0);
  const double contact[3] = {step.at_mm[0], step.at_mm[1], 0.0};
  const int si = static_cast<int>(side);
  ArmIk ik(m, side);
  const Hand open{};  // the sequence's open hand
  REQUIRE(ik.set_tool(static_cast<ToolFrame>(step.tool), ik.options().rest_rad, open));
  ArmIk::Joints q{};
  REQUIRE(ik.solve(sheet_goal(sheet, contact, orientation), ik.options().rest_rad, q).converged);
  world::WorldParams p;
  p.table_height_mm = l.table_mm;
  p.hand_contacts = false;  // where the arm puts the hand, nothing deflecting it
  p.randomise = false;
  for (int j = 0; j < robot::kArmJoints; ++j) p.initial_arm_rad[si][j] = q[j];
  world::World w(m, p);
  w.step_rt();
  const double cover_k = world::WorldParams{}.contact_stiffness_n_per_mm3.at(m.params().side(side).cover);
  double cover = 1e9, shell = 1e9;
  Clearance c;
  for (const world::WorldShape& s : w.shapes()) {
    if (s.side != si) continue;
    const double z = world::lowest_point(s.geom, s.pose1).z;
    if (s.stiffness_n_per_mm3 == cover_k) {
      cover = std::min(cover, z);
    } else if (s.role != world::ShapeRole::arm && z < shell) {
      shell = z;
      c.lowest_shell = w.kinematics(side).link_name(s.link);
    }
  }
  c.shell_over_cover_mm = shell - cover;
  return c;
}

TEST_CASE("at the shift's contact the open hand touches the sheet with its fingertip covers only, its shells clear by more than the descent's depth") {
  const robot::RobotModel m = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  const fold::FoldSpec f = fold::load_fold_file(kConfig + "folds/half.yaml");
  // As shipped: the palm pitched 30 deg (the fingers down, the wrist up).
  const Clearance shipped = contact_clearance(m, shifting(f), f.shift, f.shift.orientation);
  MESSAGE("half: the lowest shell (" << shipped.lowest_shell << ") " << shipped.shell_over_cover_mm
                                     << " mm over the lowest fingertip cover");
  CHECK(shipped.shell_over_cover_mm > f.shift.contact_depth_mm);
  // Failing variant: the pad flat on the sheet, the fingers along world +y as shipped (turned
  // about the normal only): the forearm's flange shell, the thumb, wrist and palm hang below the pads.
  const double flat[4] = {0, 0, 0.70711, 0.70711};
  const Clearance before = contact_clearance(m, shifting(f), f.shift, flat);
  MESSAGE("half, the pad flat: the lowest shell (" << before.lowest_shell << ") " << before.shell_over_cover_mm
                                                   << " mm over the lowest fingertip cover");
  CHECK(before.shell_over_cover_mm < 0.0);
}

// The pinching hand's touches after the fold (the swipe's, the hardening's): the open hand over
// the stack by the crease, where the laid layer's loop stands. A trial (seed 15) with the pad flat
// (as parked): the thumb's proximal phalanx, as low as the index pad, met the stack first, the
// wrist turned 32 deg and the index pad rose 75 mm while the arm went down: the descent ended at
// its depth untouched (`no_contact`).
TEST_CASE(
    "at the swipe's and the hardening's contact the pinching hand touches with its fingertip "
    "covers only") {
  const robot::RobotModel m = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  const fold::FoldSpec f = fold::load_fold_file(kConfig + "folds/half.yaml");
  fold::ContactStep harden = f.harden;  // its stroke's start: the intended crease, inset and offset
  harden.at_mm[0] = f.fold_line_mm[0][0] + f.harden_inset_mm;
  harden.at_mm[1] = f.fold_line_mm[0][1] + f.harden_offset_mm;
  for (const fold::ContactStep* step : {&f.swipe, static_cast<const fold::ContactStep*>(&harden)}) {
    const Clearance c = contact_clearance(m, pinching(f), *step, step->orientation);
    MESSAGE("half, pinching hand at ("
            << step->at_mm[0] << ", " << step->at_mm[1] << "): the lowest shell (" << c.lowest_shell
            << ") " << c.shell_over_cover_mm << " mm over the lowest fingertip cover");
    CHECK(c.shell_over_cover_mm > step->contact_depth_mm);
    // Failing variant: the pad flat, as parked.
    const double flat[4] = {0, 0, 0.70711, 0.70711};
    CHECK(contact_clearance(m, pinching(f), *step, flat).shell_over_cover_mm <
          step->contact_depth_mm);
  }
}

namespace {

// The bend of FOLD as arm_motion checks it: the pinching tool at the grasp (the shaped hand, from
// the parked pose through above_via, above the edge and round the overhang, as the grasp test
// above), the thumb closed by pinch_rad, then each via point in turn (path_failures at the
// fold's limits). The sheet as the shift leaves it, turned YAW_DEG. UNTURNED: each via's
// orientation with the pinch's own turn taken out (the sheet's turn alone, applied to the pad as
// if it pressed flat). UNLIMITED: the pad turning all the way with the sheet, not within the
// fold file's yaw range (fold_sequence's Machine::via_orientation). Returns how many via points
// are not reached.
int bend_failures(const robot::RobotModel& m, const fold::FoldSpec& f, double yaw_deg,
                  bool unturned, bool unlimited = false) {
  const double yaw = yaw_deg * std::numbers::pi / 180.0;
  const KDL::Frame sheet = shifted_sheet(layout(), f, yaw);
  ArmIk ik(m, pinching(f));
  ArmIk::Joints q{};
  REQUIRE(grasp_failures(ik, q, f, sheet) == 0);
  REQUIRE(ik.set_tool(static_cast<ToolFrame>(f.grasp_tool), q, posture(f.pinch_rad)));
  const KDL::Frame from = ik.tool_pose(q);
  const KDL::Rotation pinched = sheet.M.Inverse() * from.M;  // the pinched pad in the sheet frame
  // The pad's turn with the sheet's heading kept within the yaw range: turned back about the
  // vertical by the excess (the sheet's u axis, as the sequence's frame has it).
  double back = 0;
  if (f.bend_yaw_limited && !unlimited) {
    const KDL::Vector u = sheet.M.UnitX();
    const double heading = std::remainder(
        std::atan2(u.y(), u.x()) - f.bend_yaw_reference_deg * std::numbers::pi / 180.0,
        2 * std::numbers::pi);
    const double kept = std::clamp(heading, f.bend_yaw_range_deg[0] * std::numbers::pi / 180.0,
                                   f.bend_yaw_range_deg[1] * std::numbers::pi / 180.0);
    back = kept - heading;
  }
  std::vector<KDL::Frame> via;
  for (int k = 0; k < f.via_count; ++k) {
    const double* vq = f.via_orientation[k];
    KDL::Rotation r = KDL::Rotation::Quaternion(vq[0], vq[1], vq[2], vq[3]);
    if (unturned) r = r * pinched.Inverse();
    const KDL::Frame g =
        sheet * KDL::Frame(r, KDL::Vector(f.via_mm[k][0], f.via_mm[k][1], f.via_mm[k][2]) / 1000.0);
    via.push_back(KDL::Frame(KDL::Rotation::RotZ(back) * g.M, g.p));
  }
  const std::string what = f.name + (unturned ? " (unturned)" : "") +
                           (unlimited ? " (unlimited)" : "") + " yaw " + std::to_string(yaw_deg);
  return path_failures(ik, q, from, via, f.fold, what);
}

}  // namespace

// The half fold's via points up to the pinch turned 120 deg (the first five). Past them this
// model (KDL tracking, 3 tries a step) loses the arm at the 150 deg point while arm_motion's own
// check accepts the whole bend (crease-trials: the world's bend through all eight); the model is
// stricter there, not arm_motion laxer (the world fold follows the same circle, sim_world_fold).
constexpr int kBendCheckedVia = 5;

TEST_CASE("the bend's path from the pinch reaches the half fold's via points to 120 deg within the limits and speeds, at every turn of the sheet") {
  const robot::RobotModel m = robot::RobotModel::load(kConfig + "robot/crease_robot.yaml");
  const fold::FoldSpec half = fold::load_fold_file(kConfig + "folds/half.yaml");
  REQUIRE(half.via_count >= kBendCheckedVia);
  REQUIRE(half.bend_yaw_limited);
  // Every yaw the world draws (+-15 deg) and the further turn the shift gives it (to -18.5 deg in
  // the trials).
  for (double yaw_deg : {-20.0, -18.0, -15.0, 0.0, 15.0, 18.0}) {
    CAPTURE(yaw_deg);
    const int missed = bend_failures(m, half, yaw_deg, false);
    MESSAGE("yaw " << yaw_deg << ": " << missed << " of " << half.via_count << " via points not reached by the model");
    CHECK(missed <= half.via_count - kBendCheckedVia);
  }
  // Failing variants: the via points as the sheet's turn alone (the pad as if flat on the sheet):
  // lost before the first five; the pad turning all the way with a sheet at -18 deg: lost at the
  // bend's top (the trials' arm_r goal refused at via[4]).
  for (double yaw_deg : {0.0, -15.0, 15.0}) CHECK(bend_failures(m, half, yaw_deg, true) > half.via_count - kBendCheckedVia);
  CHECK(bend_failures(m, half, -18.0, false, true) > half.via_count - kBendCheckedVia);
}
