// crease-bench world: the two scenes' commands (bench_world_scene.h). Non-RT, before timing.
#include "bench_world_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "plugins/robot_model/arm_ik.h"
#include "plugins/sim_world/reference_poses.h"
#include "plugins/sim_world/side_kinematics.h"

namespace crease::bench::world_scene {

namespace {

using Vec3 = sheet::Vec3;
using robot::Side;
using world::SideKinematics;

double deg(double d) { return d * std::numbers::pi / 180.0; }

using namespace crease::world::poses;

// A side's tool path: the index pad's point (mm) and the hand's angles at every step.
// PALM, when not empty, turns the palm per step (else the script's palm for the side holds).
struct Path {
  std::vector<Vec3> pad;
  std::vector<HandQ> hand;
  std::vector<KDL::Rotation> palm;
  void push(Vec3 p, const HandQ& h) {
    pad.push_back(p);
    hand.push_back(h);
    if (!palm.empty()) palm.push_back(palm.back());
  }
  void line(Vec3 to, double speed_mm_s, double dt_s) {
    const Vec3 from = pad.back();
    const int n = std::max(1, static_cast<int>(std::ceil(sheet::norm(to - from) / (speed_mm_s * dt_s))));
    for (int i = 1; i <= n; ++i)
      push(from + (static_cast<double>(i) / n) * (to - from), hand.back());
  }
  void hold(double s, double dt_s) {
    for (long i = 0, n = std::lround(s / dt_s); i < n; ++i) push(pad.back(), hand.back());
  }
  // The thumb's THJ5 from where it is to TO in RAMP_S, then held for SETTLE_S.
  void thumb(double to, double ramp_s, double settle_s, double dt_s) {
    const double from = hand.back()[THJ5];
    const long n = std::max(1L, std::lround(ramp_s / dt_s));
    for (long i = 1; i <= n; ++i) {
      HandQ h = hand.back();
      h[THJ5] = from + (to - from) * static_cast<double>(i) / static_cast<double>(n);
      push(pad.back(), h);
    }
    hold(settle_s, dt_s);
  }
  void pad_to(std::size_t n) {
    pad.resize(n, pad.back());
    hand.resize(n, hand.back());
    if (!palm.empty()) palm.resize(n, palm.back());
  }
};

// The arm's angles for every step of PATH: the index pad at the point with the palm link turned
// to PALM (the pad's offset from the palm taken from the path's first hand posture).
// TOL_MM: how near each step's pad must get (the fold's turned pinch passes near the arm's
// singular postures).
bool solve_arm(const robot::RobotModel& model, Side side, const Path& path,
               const KDL::Rotation& fixed_palm, std::vector<std::array<ArmQ, 2>>& arm,
               double tol_mm) {
  robot::ArmIk ik(model, side);
  ArmQ q = ik.options().rest_rad;
  const ArmQ guess = q;
  SideKinematics kin(model, side);
  kin.update_rt(q, path.hand.front());
  const std::string prefix = model.params().side(side).prefix;
  const KDL::Frame world_palm = to_kdl_frame(kin.link_pose(kin.link_index(prefix + "palm")));
  ik.set_tool(robot::ToolFrame::ff_pad, q, path.hand.front());
  const KDL::Frame palm_pad = world_palm.Inverse() * ik.tool_pose(q);
  arm.resize(path.pad.size());
  for (std::size_t k = 0; k < path.pad.size(); ++k) {
    const Vec3 p = path.pad[k];
    const KDL::Rotation& palm = path.palm.empty() ? fixed_palm : path.palm[k];
    const KDL::Frame target = KDL::Frame(palm, KDL::Vector(p.x, p.y, p.z) / 1000.0 - palm * palm_pad.p) * palm_pad;
    robot::ArmIk::Result r = k == 0 ? ik.solve(target, guess, q) : ik.track(target, q);
    if (!(r.error_m < 1e-3 * tol_mm) && k > 0)
      r = ik.solve(target, q, q);  // tracking lost: from here
    if (!(r.error_m < 1e-3 * tol_mm)) {
      std::printf("world: the %s arm does not reach (%.1f, %.1f, %.1f) mm (error %.3f mm)\n",
                  side == Side::right ? "right" : "left", p.x, p.y, p.z, 1000 * r.error_m);
      return false;
    }
    arm[k][static_cast<int>(side)] = q;
  }
  return true;
}

bool finish(const robot::RobotModel& model, const std::array<Path, 2>& paths,
            const std::array<KDL::Rotation, 2>& palm, Script& out, double tol_mm = 0.01) {
  for (int s = 0; s < 2; ++s) {
    if (!solve_arm(model, static_cast<Side>(s), paths[s], palm[s], out.arm, tol_mm)) return false;
  }
  out.hand.resize(paths[0].hand.size());
  for (std::size_t k = 0; k < out.hand.size(); ++k) out.hand[k] = {paths[0].hand[k], paths[1].hand[k]};
  for (int s = 0; s < 2; ++s) {
    out.params.initial_arm_rad[s] = out.arm.front()[s];
    out.params.initial_hand_rad[s] = out.hand.front()[s];
  }
  return true;
}

}  // namespace

bool press_drag_script(const robot::RobotModel& model, bool quick, Script& out) {
  out.name = quick ? "press (quick)" : "press_drag";
  out.params.randomise = false;
  out.params.initial_stiffness_nm_per_rad = 2.0;
  for (HandQ& k : out.stiffness) k.fill(2.0);
  const double dt = out.params.dt_s;
  std::array<Path, 2> p{Path{{{40, 40, 8}}, {index_out()}}, Path{{{-40, -40, 8}}, {index_out()}}};
  for (Path& k : p) {
    k.line({k.pad[0].x, k.pad[0].y, -6}, 10.0, dt);
    k.hold(0.3, dt);
  }
  if (!quick) {
    p[0].line({40, 0, -6}, 20.0, dt);
    p[1].hold(2.0, dt);
    for (Path& k : p) {
      k.hold(0.3, dt);
      k.line({k.pad.back().x, k.pad.back().y, 14}, 20.0, dt);
      k.hold(0.5, dt);
    }
  }
  const std::size_t n = std::max(p[0].pad.size(), p[1].pad.size());
  for (Path& k : p) k.pad_to(n);
  out.probes = {{40, 40, 0}, {-40, -40, 0}};
  return finish(model, p, {palm_forward_down(deg(30)), palm_forward_down(deg(30))}, out);
}

bool pinch_script(const robot::RobotModel& model, Script& out) {
  out.name = "pinch";
  out.params.randomise = false;
  out.params.table_extent_mm = {-world::WorldParams::kNoEdge, world::WorldParams::kNoEdge, -95.0,
                                world::WorldParams::kNoEdge};
  out.params.initial_stiffness_nm_per_rad = 1.0;
  for (HandQ& k : out.stiffness) k.fill(1.0);
  const double dt = out.params.dt_s;
  const KDL::Rotation right_palm = pinch_palm(model, pinch_hand(0.696));  // thumb pad straight down

  const Vec3 at{87, -134, -8};  // under the corner, 48.5 mm over the near edge
  std::array<Path, 2> p{Path{{at}, {pinch_hand(0.3)}}, Path{{{-40, 60, 8}}, {index_out()}}};
  p[0].hold(0.3, dt);
  p[0].line({at.x, at.y, -1.2}, 10.0, dt);
  p[0].hold(0.1, dt);
  for (int i = 1; i <= 500; ++i) {  // the thumb closes in 0.4 s, 0.1 s more to settle
    HandQ h = p[0].hand.back();
    h[THJ5] = 0.3 + (0.77 - 0.3) * std::min(1.0, i / 400.0);
    p[0].pad.push_back(p[0].pad.back());
    p[0].hand.push_back(h);
  }
  out.mark_step = p[0].pad.size() - 1;
  p[0].line({at.x, at.y, 48.8}, 5.0, dt);
  p[0].hold(0.2, dt);
  p[1].line({-40, 60, -6}, 10.0, dt);  // the left presses the far half while the right works
  const std::size_t steps = std::max(p[0].pad.size(), p[1].pad.size());
  for (Path& q : p) q.pad_to(steps);
  out.probes = {{at.x, at.y, 0}, {-40, 60, 0}};
  return finish(model, p, {right_palm, palm_forward_down(deg(30))}, out);
}

bool fold_script(const robot::RobotModel& model, Script& out) {
  out.name = "fold";
  out.params.randomise = false;
  // The sheet's far edge 33.5 mm over the table's; the table's near edge 101.5 mm beyond the
  // sheet's, so that the right forearm, turned down towards the robot as the pinch lays the layer,
  // passes beyond it (over a table without that edge it would hang 88 mm under its top).
  out.params.table_extent_mm = {-world::WorldParams::kNoEdge, world::WorldParams::kNoEdge, -250.0,
                                115.0};
  out.params.initial_stiffness_nm_per_rad = 3.0;
  for (HandQ& k : out.stiffness) k.fill(3.0);
  const double dt = out.params.dt_s;
  // The right pinch turned about z to reach the far edge from beyond it (sim_world_fold's grasp),
  // the left index on the near half, 60 mm from its left edge and from the crease.
  const KDL::Rotation palm0 =
      KDL::Rotation::RotZ(std::numbers::pi) * pinch_palm(model, pinch_hand(0.696));
  const Vec3 at{0, 134, -1.2};  // the index pad under the far edge's middle, 14.5 mm inside it
  std::array<Path, 2> p{Path{{{0, 190, 40}}, {pinch_hand(0.0)}, {palm0}},
                        Path{{{-60, -60, 8}}, {index_out()}, {}}};
  // Presses the near half 10 mm into the table (index_out): at 6 mm, since the table's edges were
  // rounded, the bend dragged the near half 52.9 mm and the fold was lost (the square far edge had
  // caught the paper and held the sheet with the index).
  p[1].line({-60, -60, -10}, 10.0, dt);
  p[0].hold(0.3, dt);
  p[0].line({0, 190, -35}, 40.0, dt);  // round the drooping overhang: down beyond it, in, up
  p[0].line({0, 134, -35}, 40.0, dt);
  p[0].line(at, 10.0, dt);
  p[0].hold(0.1, dt);
  p[0].thumb(0.77, 0.4, 0.1, dt);  // the pinch closes
  out.mark_step = p[0].pad.size() - 1;
  // The bend: 6 s on a half circle of 134 mm about the crease line (y = 0), 15 % shorter at the
  // top, the pinch turning with the sheet up to 120 deg.
  const long n = std::lround(6.0 / dt);
  for (long i = 1; i <= n; ++i) {
    const double th = std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
    const double r = at.y * (1.0 - 0.15 * std::sin(th));
    p[0].push({at.x, r * std::cos(th), at.z + r * std::sin(th)}, p[0].hand.back());
    p[0].palm.back() = KDL::Rotation::RotX(std::min(deg(120), th)) * palm0;
  }
  p[0].hold(0.5, dt);
  out.mark2_step = p[0].pad.size() - 1;
  p[1].pad_to(p[0].pad.size());
  p[1].line({-150, -60, -6}, 45.0, dt);  // out from under the laid layer, off the sheet's side
  p[0].pad_to(p[1].pad.size());
  p[0].thumb(0.0, 0.3, 0.2, dt);  // the pinch opens, the hand withdraws, both hands leave
  p[0].line(p[0].pad.back() + Vec3{0, 0, 25}, 20.0, dt);
  p[1].pad_to(p[0].pad.size());
  p[1].line(p[1].pad.back() + Vec3{0, 0, 60}, 50.0, dt);
  p[1].hold(3.0, dt);
  p[0].pad_to(p[1].pad.size());
  out.probes = {{at.x, at.y, 0}, {-60, -60, 0}};
  return finish(model, p, {palm0, palm_forward_down(deg(30))}, out, 0.5);
}

}  // namespace crease::bench::world_scene
