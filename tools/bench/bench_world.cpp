// crease-bench world: the simulated world's cost per simulated second with both hands in
// contact with the sheet, next to MuJoCo 2.2.2 simulating the same scene in the same run.
//
// The scene (bench_world_scene.h): both index fingertips press the sheet, the right (rubber)
// drags it 40 mm while the left (fabric) keeps pressing, both lift. Ours runs first (its hand
// shapes' poses recorded per step), then MuJoCo replays those poses with mocap bodies over its
// composite-grid cloth of the same nodes. Both on one CPU (pinned when the machine allows),
// 1 ms steps. Printed: both real-time factors (simulated s / wall s), and both sheets' end
// states: how far the patch under the right fingertip moved (it should follow the rubber
// finger), how far the patch under the left moved (fabric: it should stay while the sheet is
// dragged under it, within what the sheet's pull drags), the sheet's centroid shift, its lowest
// node. Not in the scene yet: a pinch and a fold (their scripted scenes are the sim_world
// tests'); MuJoCo's grid cloth has no bending stiffness and no plasticity, so it could not
// keep a crease in any case.
//
//   crease-bench world [--quick] [--mj-solver CG|PGS|Newton] [--mj-iterations N] [--cpu K]
// --quick: the first 1.5 simulated seconds (descent and press) only.
// Last line: world: ours_rtf=... mujoco_rtf=... ratio=... ours_drag_mm=... mujoco_drag_mm=...
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "bench_registry.h"
#include "bench_util.h"
#include "bench_world_scene.h"
#include "plugins/robot_model/arm_ik.h"
#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/sim_world.h"

namespace {

using namespace crease;
using namespace crease::world;
using namespace crease::bench::world_scene;
using Vec3 = crease::sheet::Vec3;
using robot::Side;

constexpr double kPi = std::numbers::pi;
double deg(double d) { return d * kPi / 180.0; }

// A rotation from its z axis and a vector near its x axis.
KDL::Rotation frame_from_z_x(KDL::Vector z, KDL::Vector x) {
  z.Normalize();
  x = x - KDL::dot(x, z) * z;
  x.Normalize();
  return KDL::Rotation(x, z * x, z);
}

KDL::Frame to_frame(const Pose& p) {
  return KDL::Frame(KDL::Rotation(p.r[0], p.r[1], p.r[2], p.r[3], p.r[4], p.r[5], p.r[6], p.r[7], p.r[8]),
                    KDL::Vector(p.t.x, p.t.y, p.t.z) / 1000.0);
}

// One side's script: the index pad's target points (mm) at the end of every step.
struct SideScript {
  Side side;
  std::vector<Vec3> pad_mm;
};

void append_line(std::vector<Vec3>& path, Vec3 to, double speed_mm_s, double dt_s) {
  const Vec3 from = path.back();
  const double len = sheet::norm(to - from);
  const int n = std::max(1, static_cast<int>(std::ceil(len / (speed_mm_s * dt_s))));
  for (int i = 1; i <= n; ++i) path.push_back(from + (static_cast<double>(i) / n) * (to - from));
}
void append_hold(std::vector<Vec3>& path, double s, double dt_s) {
  const int n = static_cast<int>(std::lround(s / dt_s));
  for (int i = 0; i < n; ++i) path.push_back(path.back());
}

// Both sides' scripts, of equal length. Sheet top at z ~ 0.1 mm.
std::array<SideScript, 2> script(double dt_s, bool quick) {
  std::array<SideScript, 2> s{SideScript{Side::right, {{40, 40, 8}}}, SideScript{Side::left, {{-40, -40, 8}}}};
  for (SideScript& k : s) {
    append_line(k.pad_mm, {k.pad_mm[0].x, k.pad_mm[0].y, -6}, 10.0, dt_s);  // 1.4 s
    append_hold(k.pad_mm, 0.3, dt_s);
  }
  if (!quick) {
    append_line(s[0].pad_mm, {40, 0, -6}, 20.0, dt_s);  // the drag: 2 s
    append_hold(s[1].pad_mm, 2.0, dt_s);
    for (SideScript& k : s) {
      append_hold(k.pad_mm, 0.3, dt_s);
      const Vec3 at = k.pad_mm.back();
      append_line(k.pad_mm, {at.x, at.y, 14}, 20.0, dt_s);
      append_hold(k.pad_mm, 0.5, dt_s);
    }
  }
  const std::size_t n = std::max(s[0].pad_mm.size(), s[1].pad_mm.size());
  for (SideScript& k : s) k.pad_mm.resize(n, k.pad_mm.back());
  return s;
}

// Only the index out: the other fingers bent back to their J3 limit (-15 deg); §3 order.
World::HandJoints index_out() {
  World::HandJoints h{};
  h[6] = h[9] = h[13] = deg(-15);  // MFJ3, RFJ3, LFJ3
  return h;
}

// The arm's angles for every step of SCRIPT: the index pad at the point, the palm turned
// forward and 30 deg down. Returns false when a pose was not reached.
bool solve_arm(const robot::RobotModel& model, const SideScript& script, const World::HandJoints& hand,
               std::vector<World::ArmJoints>& out) {
  robot::ArmIk ik(model, script.side);
  const double beta = deg(30);
  const KDL::Rotation palm = frame_from_z_x({0, std::cos(beta), -std::sin(beta)}, {-1, 0, 0});
  World::ArmJoints q = ik.options().rest_rad, guess = q;
  // The pad's frame relative to the palm link's for this hand posture.
  SideKinematics kin(model, script.side);
  kin.update_rt(q, hand);
  const std::string prefix = model.params().side(script.side).prefix;
  const KDL::Frame world_palm = to_frame(kin.link_pose(kin.link_index(prefix + "palm")));
  ik.set_tool(robot::ToolFrame::ff_pad, q, hand);
  const KDL::Frame palm_pad = world_palm.Inverse() * ik.tool_pose(q);
  out.clear();
  out.reserve(script.pad_mm.size());
  for (std::size_t k = 0; k < script.pad_mm.size(); ++k) {
    const Vec3 p = script.pad_mm[k];
    const KDL::Vector pm(p.x / 1000, p.y / 1000, p.z / 1000);
    const KDL::Frame target = KDL::Frame(palm, pm - palm * palm_pad.p) * palm_pad;
    const robot::ArmIk::Result r = k == 0 ? ik.solve(target, guess, q) : ik.track(target, q);
    if (!(r.error_m < 1e-5)) {
      std::printf("world: the %s arm does not reach (%.1f, %.1f, %.1f) mm (error %.3f mm)\n",
                  script.side == Side::right ? "right" : "left", p.x, p.y, p.z, 1000 * r.error_m);
      return false;
    }
    out.push_back(q);
  }
  return true;
}

void pin_to_cpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (pthread_setaffinity_np(pthread_self(), sizeof set, &set) != 0) std::printf("world: not pinned to CPU %d\n", cpu);
}

// The node of START nearest P (xy), its index.
std::size_t nearest(const std::vector<Vec3>& start, Vec3 p) {
  std::size_t best = 0;
  double d_best = 1e18;
  for (std::size_t i = 0; i < start.size(); ++i) {
    const double dx = start[i].x - p.x, dy = start[i].y - p.y, d = dx * dx + dy * dy;
    if (d < d_best) d_best = d, best = i;
  }
  return best;
}
double moved_xy(const SheetEnd& s, std::size_t i) {
  return std::hypot(s.end[i].x - s.start[i].x, s.end[i].y - s.start[i].y);
}
Vec3 centroid(const std::vector<Vec3>& v) {
  Vec3 c;
  for (const Vec3& p : v) c += p;
  return (1.0 / static_cast<double>(v.size())) * c;
}

struct Figures {
  double right_patch_mm = 0, left_patch_mm = 0, centroid_mm = 0;
};
Figures figures(const SheetEnd& s, const ScenePoints& pts) {
  Figures f;
  f.right_patch_mm = moved_xy(s, nearest(s.start, pts.right_press));
  f.left_patch_mm = moved_xy(s, nearest(s.start, pts.left_press));
  const Vec3 c0 = centroid(s.start), c1 = centroid(s.end);
  f.centroid_mm = std::hypot(c1.x - c0.x, c1.y - c0.y);
  return f;
}

int run_world(int argc, char** argv) {
  const bool quick = bench::has_flag(argc, argv, "--quick");
  MujocoOptions mo;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--mj-solver") == 0) mo.solver = argv[i + 1];
  }
  mo.iterations = static_cast<int>(bench::arg_double(argc, argv, "--mj-iterations", mo.iterations));
  pin_to_cpu(static_cast<int>(bench::arg_double(argc, argv, "--cpu", 1)));

  const auto model = robot::RobotModel::load(std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml");
  WorldParams p;
  p.randomise = false;
  p.initial_stiffness_nm_per_rad = 2.0;
  const std::array<SideScript, 2> sides = script(p.dt_s, quick);
  const World::HandJoints hand = index_out();
  std::array<std::vector<World::ArmJoints>, 2> arm;
  for (int s = 0; s < 2; ++s) {
    if (!solve_arm(model, sides[s], hand, arm[s])) return 1;
    p.initial_arm_rad[s] = arm[s].front();
    p.initial_hand_rad[s] = hand;
  }
  World w(model, p);
  World::HandJoints stiffness;
  stiffness.fill(2.0);

  // Mirror every hand shape below the wrist (fingers, pads, backs, palm) for MuJoCo.
  std::vector<MirroredShape> mirror;
  std::vector<std::size_t> mirrored;
  for (std::size_t i = 0; i < w.shapes().size(); ++i) {
    const WorldShape& sh = w.shapes()[i];
    if (sh.role == ShapeRole::arm || sh.role == ShapeRole::hand) continue;
    mirrored.push_back(i);
    mirror.push_back({sh.geom, sh.friction, {}});
    mirror.back().poses.reserve(arm[0].size());
  }

  SheetEnd ours;
  ours.start.assign(w.sheet().positions().begin(), w.sheet().positions().end());
  ScenePoints pts{{40, 40, 0}, {-40, -40, 0}};
  std::vector<double> step_us;
  step_us.reserve(arm[0].size());
  double max_pen = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < arm[0].size(); ++k) {
    const auto s0 = std::chrono::steady_clock::now();
    for (int s = 0; s < 2; ++s) {
      w.command_arm_rt(static_cast<Side>(s), arm[s][k]);
      w.command_hand_rt(static_cast<Side>(s), hand, stiffness);
    }
    w.step_rt();
    step_us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - s0).count());
    // Recording is outside the per-step figure but inside the total (a copy of ~60 poses).
    for (std::size_t j = 0; j < mirrored.size(); ++j) mirror[j].poses.push_back(w.shapes()[mirrored[j]].pose1);
    max_pen = std::max(max_pen, w.max_penetration_mm());
  }
  ours.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ours.simulated_s = static_cast<double>(arm[0].size()) * p.dt_s;
  ours.end.assign(w.sheet().positions().begin(), w.sheet().positions().end());
  ours.lowest_z_mm = 1e9;
  for (const Vec3& q : ours.end) ours.lowest_z_mm = std::min(ours.lowest_z_mm, q.z);
  std::sort(step_us.begin(), step_us.end());
  const auto pct = [&](double f) { return step_us[static_cast<std::size_t>(f * static_cast<double>(step_us.size() - 1))]; };
  const WorldState& st = w.state();
  std::printf("world: scene %s, %.2f simulated s, %zu steps of 1 ms, %zu hand shapes mirrored, sheet %d x %d nodes\n",
              quick ? "press (quick)" : "press, drag, lift", ours.simulated_s, arm[0].size(), mirror.size(),
              p.sheet.grid.nodes_u, p.sheet.grid.nodes_v);
  std::printf("ours:   %.2f s wall, rtf %.2f; step p50 %.0f us, p99 %.0f us, max %.0f us; worst depth into the sheet "
              "%.2f mm; rollbacks %u\n",
              ours.wall_s, ours.rtf(), pct(0.5), pct(0.99), step_us.back(), max_pen, st.rollbacks);

  SheetEnd theirs;
  mo.sheet_thickness_mm = p.sheet.grid.thickness_mm;
  const double spacing = p.sheet.grid.width_mm / (p.sheet.grid.nodes_u - 1);
  const double mass = p.sheet.grid.areal_density_g_per_m2 * 1e-3 * p.sheet.grid.width_mm * p.sheet.grid.height_mm * 1e-6;
  std::printf("mujoco: %s solver, %d iterations, particles of %.1f mm radius, grid spacing %.2f mm (ours %.2f x %.2f)\n",
              mo.solver.c_str(), mo.iterations, mo.particle_radius_mm, spacing, spacing,
              p.sheet.grid.height_mm / (p.sheet.grid.nodes_v - 1));
  if (!run_mujoco(mirror, p.dt_s, p.sheet.grid.nodes_u, p.sheet.grid.nodes_v, spacing, mass,
                  w.draws().paper_table, mo, theirs))
    return 1;
  std::printf("mujoco: %.2f s wall, rtf %.3f\n", theirs.wall_s, theirs.rtf());

  const Figures fo = figures(ours, pts), fm = figures(theirs, pts);
  std::printf("\n%-34s %10s %10s\n", "end state", "ours", "mujoco");
  std::printf("%-34s %10.1f %10.1f\n", "patch under the right index (mm)", fo.right_patch_mm, fm.right_patch_mm);
  std::printf("%-34s %10.1f %10.1f\n", "patch under the left index (mm)", fo.left_patch_mm, fm.left_patch_mm);
  std::printf("%-34s %10.1f %10.1f\n", "sheet centroid shift (mm)", fo.centroid_mm, fm.centroid_mm);
  std::printf("%-34s %10.2f %10.2f\n", "lowest node centre (mm)", ours.lowest_z_mm, theirs.lowest_z_mm);
  std::printf("%-34s %10.2f %10.3f\n", "real-time factor", ours.rtf(), theirs.rtf());
  std::printf("world: ours_rtf=%.2f mujoco_rtf=%.3f ratio=%.1f ours_drag_mm=%.1f mujoco_drag_mm=%.1f "
              "ours_left_mm=%.1f mujoco_left_mm=%.1f steps=%zu\n",
              ours.rtf(), theirs.rtf(), bench::ratio(ours.rtf(), theirs.rtf()), fo.right_patch_mm, fm.right_patch_mm,
              fo.left_patch_mm, fm.left_patch_mm, arm[0].size());
  return 0;
}

}  // namespace

CREASE_BENCH(world, "the simulated world per simulated second, both hands in contact, against MuJoCo's cloth", run_world);
