// crease-bench world: the simulated world's cost per simulated second with both hands in
// contact with the sheet, next to MuJoCo 2.2.2 simulating the same scenes in the same run.
//
// The scenes (bench_world_scene.h): press_drag (both index fingertips press, the right drags the
// sheet 40 mm, the left keeps pressing), pinch (the right pinches the corner over the table's
// edge and lifts it 50 mm, the left presses the far half) and fold (the right pinches the far
// edge and folds it over onto the near half that the left index presses, then both let go). Ours
// runs each scene first, its hand shapes' poses recorded per step; MuJoCo then replays those poses
// with mocap bodies over its composite-grid cloth of the same nodes and mass. One CPU (pinned when
// the machine allows), 1 ms steps, only the steps timed. Printed per scene: both real-time factors
// (simulated s / wall s) and both sheets' end states; the real-time factors of the whole run (both
// scenes). Not in the scenes yet: a crease pressed and swiped. MuJoCo's grid cloth has no bending
// stiffness and no plasticity (its particles are joined by length constraints only), so it
// cannot keep a crease: its fold is held by gravity and friction alone.
//
//   crease-bench world [--quick] [--ours-only] [--mj-solver CG|PGS|Newton] [--mj-iterations N]
//   [--cpu K] [--scene press_drag|pinch|fold] [--ensemble N]
// --quick: press_drag's first 1.7 simulated seconds (descent and press) only.
// --scene: that scene alone, ours alone (implies --ours-only: to profile one scene).
// --ensemble N (implies --ours-only): each scene N times, the sheet laid 0.5 mm off its place in
// N - 1 directions (and once in place); per end-state figure the median and the range. The
// scenes are open-loop and chaotic where a pinch holds the sheet by a few nodes: a change to the
// world's physics is judged by the spread it leaves, not by one run.
// --ours-only: MuJoCo not run (to profile ours); ours' end states are printed, the last line
// carries ours alone.
// Last line: world: ours_rtf=... mujoco_rtf=... ratio=... drag_mm=ours/mujoco pinch_rise_mm=...
// pinch_slip_mm=... fold_slip_mm=... fold_edges_mm=... retained_deg=...
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

namespace {

using namespace crease;
using namespace crease::world;
using namespace crease::bench::world_scene;
using Vec3 = crease::sheet::Vec3;
using robot::Side;

void pin_to_cpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (pthread_setaffinity_np(pthread_self(), sizeof set, &set) != 0) std::printf("world: not pinned to CPU %d\n", cpu);
}

// The node of NODES nearest P in x and y.
std::size_t nearest(const std::vector<Vec3>& nodes, Vec3 p) {
  std::size_t best = 0;
  double d_best = 1e18;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double dx = nodes[i].x - p.x, dy = nodes[i].y - p.y, d = dx * dx + dy * dy;
    if (d < d_best) d_best = d, best = i;
  }
  return best;
}
double moved_xy(const SheetRun& s, std::size_t i) { return std::hypot(s.end[i].x - s.start[i].x, s.end[i].y - s.start[i].y); }

// Ours: the scene stepped, the hand shapes' poses recorded for MuJoCo.
SheetRun run_ours(const robot::RobotModel& model, const Script& sc, std::vector<MirroredShape>& mirror, double& table_mu) {
  World w(model, sc.params);
  table_mu = w.draws().paper_table;
  std::vector<std::size_t> mirrored;
  mirror.clear();
  for (std::size_t i = 0; i < w.shapes().size(); ++i) {
    const WorldShape& sh = w.shapes()[i];
    if (sh.role == ShapeRole::arm || sh.role == ShapeRole::hand) continue;  // fingers, pads, backs, palm
    mirrored.push_back(i);
    mirror.push_back({sh.geom, sh.friction, sh.role, sh.side, sh.fingertip, {}});
    mirror.back().poses.reserve(sc.arm.size());
  }
  SheetRun out;
  out.start.assign(w.sheet().positions().begin(), w.sheet().positions().end());
  std::vector<double> step_us;
  step_us.reserve(sc.arm.size());
  for (std::size_t k = 0; k < sc.arm.size(); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int s = 0; s < 2; ++s) {
      w.command_arm_rt(static_cast<Side>(s), sc.arm[k][s]);
      w.command_hand_rt(static_cast<Side>(s), sc.hand[k][s], sc.stiffness[s]);
    }
    w.step_rt();
    step_us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    for (std::size_t j = 0; j < mirrored.size(); ++j) mirror[j].poses.push_back(w.shapes()[mirrored[j]].pose1);
    if (k == sc.mark_step) out.mark.assign(w.sheet().positions().begin(), w.sheet().positions().end());
    if (sc.mark2_step != 0 && k == sc.mark2_step)
      out.mark2.assign(w.sheet().positions().begin(), w.sheet().positions().end());
  }
  for (double us : step_us) out.wall_s += us * 1e-6;
  out.simulated_s = static_cast<double>(sc.arm.size()) * sc.params.dt_s;
  out.end.assign(w.sheet().positions().begin(), w.sheet().positions().end());
  out.lowest_z_mm = 1e9;
  for (const Vec3& q : out.end) out.lowest_z_mm = std::min(out.lowest_z_mm, q.z);
  std::sort(step_us.begin(), step_us.end());
  const auto pct = [&](double f) { return step_us[static_cast<std::size_t>(f * static_cast<double>(step_us.size() - 1))]; };
  std::printf("  ours:   %.2f s stepping, rtf %.2f; step p50 %.0f us, p99 %.0f us, max %.0f us; deepest into the sheet "
              "%.2f mm; rollbacks %u\n",
              out.wall_s, out.rtf(), pct(0.5), pct(0.99), step_us.back(), w.max_penetration_mm(), w.state().rollbacks);
  return out;
}

// The right index pad's position at the end of step K of the recorded run.
Vec3 right_index_pad(const std::vector<MirroredShape>& mirror, std::size_t k) {
  for (const MirroredShape& m : mirror)
    if (m.side == 0 && m.fingertip == 0 && m.role == ShapeRole::pad) return m.poses[k].t;
  return {};
}

struct Row {
  std::string what;
  double ours = 0, mujoco = 0;
};

// Rows of the flat sheet by their start y: row J of NV (0: the near edge y_min) is the nodes
// within a third of the rows' spacing of y_min + J x spacing (MuJoCo's composite grid spaces its
// rows as its columns, 7.5 mm, ours 7.425: each simulator's own rows).
struct Rows {
  double y0 = 0, dy = 1;
  Rows(const SheetRun& s, int nv) {
    double lo = 1e18, hi = -1e18;
    for (const Vec3& p : s.start) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
    y0 = lo;
    dy = (hi - lo) / (nv - 1);
  }
  [[nodiscard]] bool on(const Vec3& start, int j) const {
    return std::fabs(start.y - (y0 + j * dy)) < dy / 3;
  }
};

// The mean end position of row J's nodes.
Vec3 row_end(const SheetRun& s, const Rows& rows, int j) {
  Vec3 c;
  int n = 0;
  for (std::size_t i = 0; i < s.start.size(); ++i)
    if (rows.on(s.start[i], j)) c += s.end[i], ++n;
  return n > 0 ? (1.0 / n) * c : c;
}

// The fold's angle at the crease row MID between the sheet's directions to the rows K either
// side (180: flat folded, 0: flat), from the nodes' end positions.
double fold_angle_deg(const SheetRun& s, const Rows& rows, int mid, int k) {
  const Vec3 c = row_end(s, rows, mid), a = row_end(s, rows, mid - k) - c,
             b = row_end(s, rows, mid + k) - c;
  const double cs = sheet::dot(a, b) / (sheet::norm(a) * sheet::norm(b));
  return 180.0 - std::acos(std::clamp(cs, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

// The far edge's nodes (the last row) from the near edge's (row 0) of the same column, in x and
// y at the end, mean.
double edges_apart_mm(const SheetRun& s, const Rows& rows, int nv) {
  double d = 0;
  int n = 0;
  for (std::size_t i = 0; i < s.start.size(); ++i) {
    if (!rows.on(s.start[i], nv - 1)) continue;
    std::size_t best = 0;
    double best_dx = 1e18;
    for (std::size_t j = 0; j < s.start.size(); ++j)
      if (rows.on(s.start[j], 0) && std::fabs(s.start[j].x - s.start[i].x) < best_dx)
        best_dx = std::fabs(s.start[j].x - s.start[i].x), best = j;
    d += std::hypot(s.end[i].x - s.end[best].x, s.end[i].y - s.end[best].y);
    ++n;
  }
  return n > 0 ? d / n : 0.0;
}

// End-state figures of a scene for one simulator.
std::vector<double> scene_figures(const Script& sc, const SheetRun& s, const std::vector<MirroredShape>& mirror) {
  std::vector<double> f;
  if (sc.name == "pinch") {
    const std::size_t n = nearest(s.start, sc.probes[0]);
    const Vec3 pad0 = right_index_pad(mirror, sc.mark_step), pad1 = right_index_pad(mirror, sc.arm.size() - 1);
    f.push_back(s.end[n].z - s.mark[n].z);                                  // rise of the pinched point
    f.push_back(sheet::norm((s.end[n] - pad1) - (s.mark[n] - pad0)));      // its slip against the index pad
    f.push_back(moved_xy(s, nearest(s.start, sc.probes[1])));              // the left-pressed patch
  } else if (sc.name == "fold") {
    const std::size_t n = nearest(s.start, sc.probes[0]);
    const Vec3 pad0 = right_index_pad(mirror, sc.mark_step),
               pad2 = right_index_pad(mirror, sc.mark2_step);
    const int nv = sc.params.sheet.grid.nodes_v, mid = nv / 2;
    const Rows rows(s, nv);
    f.push_back(sheet::norm((s.mark2[n] - pad2) -
                            (s.mark[n] - pad0)));  // the pinched point's slip over the bend
    f.push_back(edges_apart_mm(s, rows, nv));
    f.push_back(fold_angle_deg(s, rows, mid, mid - 4));  // the halves: rows 4 from either edge
    f.push_back(fold_angle_deg(s, rows, mid, 4));  // by the crease: 4 rows (~30 mm) either side
    f.push_back(moved_xy(s, nearest(s.start, sc.probes[1])));  // the near half under the left index
  } else {
    for (const Vec3& p : sc.probes) f.push_back(moved_xy(s, nearest(s.start, p)));
  }
  f.push_back(s.lowest_z_mm);
  return f;
}
std::vector<std::string> figure_names(const Script& sc) {
  if (sc.name == "pinch")
    return {"pinched point rise over the 50 mm lift (mm)", "pinched point slip against the index pad (mm)",
            "patch under the left index moved (mm)", "lowest node centre (mm)"};
  if (sc.name == "fold")
    return {"pinched point slip against the index pad, bend (mm)",
            "far edge from the near edge, end (mm)",
            "fold angle of the halves, 3 s after release (deg)",
            "fold angle at +-30 mm, 3 s after release (deg)",
            "near half under the left index moved (mm)",
            "lowest node centre (mm)"};
  return {"patch under the right index moved (mm)", "patch under the left index moved (mm)", "lowest node centre (mm)"};
}

int run_world(int argc, char** argv) {
  const bool quick = bench::has_flag(argc, argv, "--quick");
  std::string only;  // --scene
  MujocoOptions mo;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--mj-solver") == 0) mo.solver = argv[i + 1];
    if (std::strcmp(argv[i], "--scene") == 0) only = argv[i + 1];
  }
  const int ensemble =
      std::max(1, static_cast<int>(bench::arg_double(argc, argv, "--ensemble", 1)));
  const bool ours_only = bench::has_flag(argc, argv, "--ours-only") || !only.empty() || ensemble > 1;
  mo.iterations = static_cast<int>(bench::arg_double(argc, argv, "--mj-iterations", mo.iterations));
  pin_to_cpu(static_cast<int>(bench::arg_double(argc, argv, "--cpu", 1)));

  const auto model = robot::RobotModel::load(std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml");
  std::vector<Script> scenes(quick ? 1 : 3);
  if (!press_drag_script(model, quick, scenes[0])) return 1;
  if (!quick && !pinch_script(model, scenes[1])) return 1;
  if (!quick && !fold_script(model, scenes[2])) return 1;
  const sheet::GridParams& g = scenes[0].params.sheet.grid;
  std::printf("world: sheet %d x %d nodes (%.2f x %.2f mm apart), 1 ms steps; mujoco: composite grid of %.2f mm, %s "
              "solver, %d iterations, particles of %.1f mm radius\n",
              g.nodes_u, g.nodes_v, g.width_mm / (g.nodes_u - 1), g.height_mm / (g.nodes_v - 1),
              g.width_mm / (g.nodes_u - 1), mo.solver.c_str(), mo.iterations, mo.particle_radius_mm);

  double ours_wall = 0, theirs_wall = 0, simulated = 0;
  std::vector<std::vector<double>> ours_f, theirs_f;
  for (const Script& sc : scenes) {
    if (!only.empty() && sc.name != only) continue;
    std::printf("scene %s: %.2f simulated s\n", sc.name.c_str(), static_cast<double>(sc.arm.size()) * sc.params.dt_s);
    std::vector<MirroredShape> mirror;
    double table_mu = 0;
    const SheetRun ours = run_ours(model, sc, mirror, table_mu);
    if (ours_only) {  // ours' end state alone
      ours_wall += ours.wall_s;
      simulated += ours.simulated_s;
      std::vector<std::vector<double>> runs{scene_figures(sc, ours, mirror)};
      for (int k = 1; k < ensemble; ++k) {  // the sheet laid 0.5 mm off, direction k of N - 1
        Script moved = sc;
        const double a = 2.0 * std::numbers::pi * (k - 1) / (ensemble - 1);
        moved.params.sheet.grid.origin_mm.x += 0.5 * std::cos(a);
        moved.params.sheet.grid.origin_mm.y += 0.5 * std::sin(a);
        std::vector<MirroredShape> m;
        const SheetRun r = run_ours(model, moved, m, table_mu);
        ours_wall += r.wall_s;
        simulated += r.simulated_s;
        runs.push_back(scene_figures(moved, r, m));
      }
      const std::vector<std::string> names = figure_names(sc);
      if (ensemble > 1) std::printf("  %-52s %9s %9s %9s\n", "end state", "median", "min", "max");
      for (std::size_t i = 0; i < names.size(); ++i) {
        std::vector<double> v;
        for (const auto& f : runs) v.push_back(f[i]);
        std::sort(v.begin(), v.end());
        if (ensemble > 1)
          std::printf("  %-52s %9.2f %9.2f %9.2f\n", names[i].c_str(), v[v.size() / 2], v.front(),
                      v.back());
        else
          std::printf("  %-52s %9.2f\n", names[i].c_str(), v[0]);
      }
      continue;
    }
    SheetRun theirs;
    mo.sheet_thickness_mm = sc.params.sheet.grid.thickness_mm;
    if (!run_mujoco(sc, mirror, table_mu, mo, theirs)) return 1;
    std::printf("  mujoco: %.2f s stepping, rtf %.3f (%zu hand shapes as mocap bodies)\n", theirs.wall_s, theirs.rtf(),
                mirror.size());
    ours_wall += ours.wall_s;
    theirs_wall += theirs.wall_s;
    simulated += ours.simulated_s;
    ours_f.push_back(scene_figures(sc, ours, mirror));
    theirs_f.push_back(scene_figures(sc, theirs, mirror));
    const std::vector<std::string> names = figure_names(sc);
    std::printf("  %-52s %9s %9s\n", "end state", "ours", "mujoco");
    for (std::size_t i = 0; i < names.size(); ++i)
      std::printf("  %-52s %9.2f %9.2f\n", names[i].c_str(), ours_f.back()[i], theirs_f.back()[i]);
  }
  if (ours_only) {
    if (simulated <= 0) {
      std::fprintf(stderr, "crease-bench world: no scene named '%s'\n", only.c_str());
      return 1;
    }
    std::printf("world: ours_rtf=%.2f mujoco_rtf=n/a (--ours-only)\n", simulated / ours_wall);
    return 0;
  }
  const double ours_rtf = simulated / ours_wall, theirs_rtf = simulated / theirs_wall;
  std::printf("all scenes: %.2f simulated s; ours %.2f s (rtf %.2f), mujoco %.2f s (rtf %.3f)\n",
              simulated, ours_wall, ours_rtf, theirs_wall, theirs_rtf);
  std::printf("world: ours_rtf=%.2f mujoco_rtf=%.3f ratio=%.1f drag_mm=%.1f/%.1f", ours_rtf, theirs_rtf,
              bench::ratio(ours_rtf, theirs_rtf), ours_f[0][0], theirs_f[0][0]);
  if (!quick) {
    std::printf(
        " pinch_rise_mm=%.1f/%.1f pinch_slip_mm=%.1f/%.1f fold_slip_mm=%.1f/%.1f "
        "fold_edges_mm=%.1f/%.1f "
        "retained_deg=%.0f/%.0f\n",
        ours_f[1][0], theirs_f[1][0], ours_f[1][1], theirs_f[1][1], ours_f[2][0], theirs_f[2][0],
        ours_f[2][1], theirs_f[2][1], ours_f[2][2], theirs_f[2][2]);
  } else {
    std::printf(" (--quick: press only)\n");
  }
  return 0;
}

}  // namespace

CREASE_BENCH(world, "the simulated world per simulated second, both hands in contact, against MuJoCo's cloth", run_world);
