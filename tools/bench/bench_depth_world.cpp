// crease-bench depth_world: the depth path (issue 17) tracking the world's half fold by the
// hands: the sim_world library stepping crease-bench world's fold scene (bench_world_scene.h: the
// right pinch carries the far edge over onto the near half that the left index presses, then both
// hands let go and leave), the world's sheet (29 x 41) and the arms' and hands' collision shapes
// rendered to the two D435s of config/depth_cameras (the hands occlude the sheet, as
// camera_depth_sim draws them with `world_shapes: true`), the depth path and the sheet model
// (15 x 21) in the closed loop of bench_depth_loop.h, scored against the world's nodes under the
// model's (every second one): mean over the model's nodes, the flap's hidden side included, from
// the bend's start (where the crease is announced) to the scene's end.
//
//   crease-bench depth_world [--printed] [--no-fused] [--seconds S] [--trace] [--no-hands]
//   [--no-crease] [--no-grasp]
// Runs: no camera at all (the model with what the robot's kinematics tells it: the alternative
// the depth path must beat); depth only on a plain (blue) sheet; with --printed or by default also
// the printed sheet, markers alone and markers fused with depth (the five colour cameras also see
// the hands).
// --no-hands: the cameras do not draw the robot (nothing occludes the sheet). --no-crease: the
// model is not told the fold's crease. --no-grasp: nor where the pinch holds the sheet (by
// default, as the folding sequence does, the grasp point at the pinching hand while it holds).
// Last line: depth_world: err_mm=... worst_mm=... blind_mm=... err_markers_mm=... err_fused_mm=...
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "bench_registry.h"
#include "bench_world_scene.h"
#include "core/port_types/world_shapes.h"
#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/reference_poses.h"
#include "plugins/sim_world/robot_shapes.h"
#include "tools/bench/bench_depth_loop.h"

using namespace crease;

namespace {

// The world's fold scene stepped forward to each time asked (never back).
class WorldFeed {
 public:
  WorldFeed(const robot::RobotModel& model, const bench::world_scene::Script& sc,
            const sheet::SheetParams& sp)
      : sc_(sc),
        sp_(sp),
        world_(model, sc.params),
        shapes_(std::make_unique<crease::WorldShapes>()) {
    wu_ = sc.params.sheet.grid.nodes_u;
    wv_ = sc.params.sheet.grid.nodes_v;
    su_ = (wu_ - 1) / (sp.grid.nodes_u - 1);
    sv_ = (wv_ - 1) / (sp.grid.nodes_v - 1);
  }
  // The sheet point (u, v, mm) the pinch holds.
  void set_grasp(double u_mm, double v_mm) {
    grasp_uv_[0] = u_mm;
    grasp_uv_[1] = v_mm;
  }
  // The model's grid must be the world's, every su-th and sv-th node.
  [[nodiscard]] bool grids_match() const {
    return su_ * (sp_.grid.nodes_u - 1) == wu_ - 1 && sv_ * (sp_.grid.nodes_v - 1) == wv_ - 1;
  }
  void at(double t_s, bench::SceneAt& out) {
    const auto target = static_cast<std::size_t>(std::max(0.0, t_s / sc_.params.dt_s + 0.5));
    while (step_ < target && step_ < sc_.arm.size()) {
      for (int s = 0; s < 2; ++s) {
        world_.command_arm_rt(static_cast<robot::Side>(s), sc_.arm[step_][s]);
        world_.command_hand_rt(static_cast<robot::Side>(s), sc_.hand[step_][s], sc_.stiffness[s]);
      }
      world_.step_rt();
      ++step_;
    }
    const auto x = world_.sheet().positions();
    out.mesh.nx = wu_;
    out.mesh.ny = wv_;
    out.mesh.w_mm = sc_.params.sheet.grid.width_mm;
    out.mesh.h_mm = sc_.params.sheet.grid.height_mm;
    out.mesh.nodes.clear();
    for (const auto& p : x) out.mesh.nodes.emplace_back(p.x, p.y, p.z);
    out.truth.resize(static_cast<std::size_t>(sp_.grid.nodes_u * sp_.grid.nodes_v));
    for (int j = 0; j < sp_.grid.nodes_v; ++j)
      for (int i = 0; i < sp_.grid.nodes_u; ++i)
        out.truth[static_cast<std::size_t>(j * sp_.grid.nodes_u + i)] =
            x[static_cast<std::size_t>(j * sv_ * wu_ + i * su_)];
    // While the pinch is closed (from its closing on), its grasp point lies between the thumb's
    // and the index's pads: where the robot's kinematics puts it (the folding sequence's grasp
    // target), at the point of the sheet the scene pinches.
    out.robot_targets.clear();
    if (step_ > sc_.mark_step && step_ > 0 &&
        sc_.hand[step_ - 1][0][world::poses::joints::THJ5] > 0.7) {
      const auto& tips = world_.state().hand[0].tip;
      TargetPoints::Point p{};
      for (int c = 0; c < 3; ++c)
        p.world_mm[c] = 0.5f * (tips[0].position_mm[c] + tips[4].position_mm[c]);
      p.sheet_mm[0] = static_cast<float>(grasp_uv_[0]);
      p.sheet_mm[1] = static_cast<float>(grasp_uv_[1]);
      out.robot_targets.push_back(p);
    }
    world::export_shapes_rt(world_.shapes(), *shapes_);
    vision::shapes_of(*shapes_, out.shapes);
  }

 private:
  const bench::world_scene::Script& sc_;
  sheet::SheetParams sp_;
  world::World world_;
  std::unique_ptr<crease::WorldShapes> shapes_;
  std::size_t step_ = 0;
  int wu_ = 0, wv_ = 0, su_ = 1, sv_ = 1;
  double grasp_uv_[2] = {0, 0};
};

void print(const char* what, const bench::TrackingError& e) {
  std::printf(
      "  %-26s mean %6.2f mm, worst frame %6.2f mm (at %.1f s), end %6.2f mm; %d depth frames "
      "(%.0f targets), "
      "%d marker sets (%.0f key-points)\n",
      what, e.mean_mm, e.worst_mm, e.worst_s, e.end_mm, e.depth_frames, e.targets_mean,
      e.keypoint_sets, e.keypoints_mean);
}

int run_depth_world(int argc, char** argv) {
  bool fused = true, trace = false, hands = true, crease = true, grasp = true;
  double seconds = 0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--no-fused")) {
      fused = false;
    } else if (!std::strcmp(argv[i], "--printed")) {
      fused = true;
    } else if (!std::strcmp(argv[i], "--no-crease")) {
      crease = false;
    } else if (!std::strcmp(argv[i], "--no-grasp")) {
      grasp = false;
    } else if (!std::strcmp(argv[i], "--no-hands")) {
      hands = false;
    } else if (!std::strcmp(argv[i], "--trace")) {
      trace = true;
    } else if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr,
                   "usage: crease-bench depth_world [--printed | --no-fused] [--seconds S] "
                   "[--trace] [--no-hands] [--no-crease] [--no-grasp]\n");
      return 2;
    }
  }
  const std::string src = CREASE_SOURCE_DIR;
  const auto model = robot::RobotModel::load(src + "/config/robot/crease_robot.yaml");
  bench::world_scene::Script sc;
  if (!bench::world_scene::fold_script(model, sc)) return 1;
  sheet::SheetParams sp;  // the tracking model's defaults, where the world's unturned sheet lies
  sp.grid.origin_mm = {sc.params.sheet.grid.origin_mm.x, sc.params.sheet.grid.origin_mm.y,
                       0.5 * sp.grid.thickness_mm};
  const double dt = sc.params.dt_s;
  // The scene pinches the far edge's middle (world y = 134 on the unturned sheet: v = 14.5).
  const double grasp_u = -sp.grid.origin_mm.x + 0.0, grasp_v = sp.grid.origin_mm.y - 134.0;
  bench::LoopSetup ls;
  ls.sheet = sp;
  ls.trace = trace;
  ls.announce_crease = crease;
  ls.robot_targets = grasp;
  ls.crease_s = static_cast<double>(sc.mark_step) * dt;  // the pinch closed: the bend starts
  ls.end_s = seconds > 0 ? std::min(seconds, static_cast<double>(sc.arm.size()) * dt)
                         : static_cast<double>(sc.arm.size()) * dt;
  ls.depth.cloud.voxel_mm = 6.0;
  ls.depth.cpd.max_iterations = 15;
  ls.depth.kernel_rank = 60;
  ls.depth.kernel_cut = 20.0;
  ls.depth.cpd.sigma2_init_mm2 = 25.0;
  ls.depth.cpd.sigma2_min_mm2 = 2.0;
  std::printf(
      "depth_world: the world's half fold by the hands (%.1f s, the bend from %.1f s), two D435s, "
      "hands "
      "drawn\n",
      ls.end_s, ls.crease_s);
  const auto run = [&](bool printed, bool depth, bool markers) {
    WorldFeed feed(model, sc, sp);
    feed.set_grasp(grasp_u, grasp_v);
    if (!feed.grids_match()) {
      std::fprintf(stderr, "depth_world: the model's grid is not every n-th node of the world's\n");
      std::exit(1);
    }
    ls.printed = printed;
    ls.scene = [&feed, hands](double t, bench::SceneAt& out) {
      feed.at(t, out);
      if (!hands) out.shapes.clear();
    };
    return bench::track_sheet(ls, depth, markers);
  };
  const bench::TrackingError blind = run(false, false, false);
  print("no camera (grasp only):", blind);
  const bench::TrackingError plain = run(false, true, false);
  print("plain sheet, depth:", plain);
  char markers_mm[32] = "na", fused_mm[32] = "na";
  if (fused) {
    const bench::TrackingError m = run(true, false, true);
    print("printed, markers alone:", m);
    const bench::TrackingError md = run(true, true, true);
    print("printed, markers + depth:", md);
    std::snprintf(markers_mm, sizeof markers_mm, "%.2f", m.mean_mm);
    std::snprintf(fused_mm, sizeof fused_mm, "%.2f", md.mean_mm);
  }
  std::printf(
      "depth_world: err_mm=%.2f worst_mm=%.2f blind_mm=%.2f err_markers_mm=%s err_fused_mm=%s\n",
      plain.mean_mm, plain.worst_mm, blind.mean_mm, markers_mm, fused_mm);
  return 0;
}

}  // namespace

CREASE_BENCH(
    depth_world,
    "depth path tracking the world's half fold by the hands (hands occluding), plain and printed",
    run_depth_world);
