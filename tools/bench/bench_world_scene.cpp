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
struct Path {
  std::vector<Vec3> pad;
  std::vector<HandQ> hand;
  void line(Vec3 to, double speed_mm_s, double dt_s) {
    const Vec3 from = pad.back();
    const int n = std::max(1, static_cast<int>(std::ceil(sheet::norm(to - from) / (speed_mm_s * dt_s))));
    for (int i = 1; i <= n; ++i) {
      pad.push_back(from + (static_cast<double>(i) / n) * (to - from));
      hand.push_back(hand.back());
    }
  }
  void hold(double s, double dt_s) {
    for (long i = 0, n = std::lround(s / dt_s); i < n; ++i) {
      pad.push_back(pad.back());
      hand.push_back(hand.back());
    }
  }
  void pad_to(std::size_t n) {
    pad.resize(n, pad.back());
    hand.resize(n, hand.back());
  }
};

// The arm's angles for every step of PATH: the index pad at the point with the palm link turned
// to PALM (the pad's offset from the palm taken from the path's first hand posture).
bool solve_arm(const robot::RobotModel& model, Side side, const Path& path, const KDL::Rotation& palm,
               std::vector<std::array<ArmQ, 2>>& arm) {
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
    const KDL::Frame target = KDL::Frame(palm, KDL::Vector(p.x, p.y, p.z) / 1000.0 - palm * palm_pad.p) * palm_pad;
    const robot::ArmIk::Result r = k == 0 ? ik.solve(target, guess, q) : ik.track(target, q);
    if (!(r.error_m < 1e-5)) {
      std::printf("world: the %s arm does not reach (%.1f, %.1f, %.1f) mm (error %.3f mm)\n",
                  side == Side::right ? "right" : "left", p.x, p.y, p.z, 1000 * r.error_m);
      return false;
    }
    arm[k][static_cast<int>(side)] = q;
  }
  return true;
}

bool finish(const robot::RobotModel& model, const std::array<Path, 2>& paths, const std::array<KDL::Rotation, 2>& palm,
            Script& out) {
  for (int s = 0; s < 2; ++s) {
    if (!solve_arm(model, static_cast<Side>(s), paths[s], palm[s], out.arm)) return false;
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

}  // namespace crease::bench::world_scene
