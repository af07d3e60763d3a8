// The closed loop of crease-bench depth (bench_depth_loop.h). The depth cameras' colour image of
// the printed sheet is its grey print (camera_depth_sim's `sheet: markers`): the mask keeps the
// bright paper, not the mid-grey table, the black markers (holes in the cloud, filled by the
// voxels around them) or the skin-coloured hands; of the plain sheet its blue.
#include "tools/bench/bench_depth_loop.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/port_types/depth_targets.h"
#include "core/port_types/keypoints.h"
#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/depth_camera.h"
#include "plugins/camera_rig/marker_layout.h"
#include "plugins/camera_rig/marker_sheet.h"
#include "plugins/sheet_model/sheet_runner.h"
#include "plugins/sim_world/scene/depth_sim_source.h"
#include "plugins/sim_world/scene/view_renderer.h"
#include "plugins/vision/keypoint_pipeline.h"

namespace crease::bench {

namespace {

sheet::Vec3 node_off(const SheetState& st, int k, const sheet::Vec3& truth) {
  return {st.position_mm[k][0] - truth.x, st.position_mm[k][1] - truth.y,
          st.position_mm[k][2] - truth.z};
}

// --trace: the model's error on the flap (rows v < half) and on the rest, the rest's mean offset
// (model less truth), and the depth targets' mean offset from the truth at their nearest nodes.
void trace_frame(const sheet::SheetParams& sp, double t_s, double err_mm, const SheetState& st,
                 const std::vector<sheet::Vec3>& truth, const DepthTargets* targets) {
  const int w = sp.grid.nodes_u, h = sp.grid.nodes_v;
  const int flap = w * (h / 2), rest = w * h - flap;
  double e_flap = 0, e_rest = 0;
  sheet::Vec3 off_rest;
  for (int k = 0; k < w * h; ++k) {
    const sheet::Vec3 d = node_off(st, k, truth[static_cast<std::size_t>(k)]);
    (k < flap ? e_flap : e_rest) += sheet::norm(d);
    if (k >= flap) off_rest += d;
  }
  int n[2] = {0, 0};
  sheet::Vec3 t_off[2];  // the flap's targets, the rest's
  for (std::uint32_t q = 0; targets != nullptr && q < targets->count; ++q) {
    const auto& tp = targets->points[q];
    const int iu = std::clamp(
        static_cast<int>(std::lround(tp.sheet_mm[0] * (w - 1) / sp.grid.width_mm)), 0, w - 1);
    const int iv = std::clamp(
        static_cast<int>(std::lround(tp.sheet_mm[1] * (h - 1) / sp.grid.height_mm)), 0, h - 1);
    const auto& p = truth[static_cast<std::size_t>(iv * w + iu)];
    const int side = iv < h / 2 ? 0 : 1;
    t_off[side] += sheet::Vec3{tp.world_mm[0] - p.x, tp.world_mm[1] - p.y, tp.world_mm[2] - p.z};
    ++n[side];
  }
  for (int side = 0; side < 2; ++side)
    if (n[side] > 0) t_off[side] = (1.0 / n[side]) * t_off[side];
  std::printf(
      "    t %5.2f s: error %6.2f mm (flap %6.2f, rest %6.2f; rest off %5.1f %5.1f %5.1f); "
      "targets: flap %d off "
      "%5.1f %5.1f %5.1f, rest %d off %5.1f %5.1f %5.1f\n",
      t_s, err_mm, e_flap / flap, e_rest / rest, off_rest.x / rest, off_rest.y / rest,
      off_rest.z / rest, n[0], t_off[0].x, t_off[0].y, t_off[0].z, n[1], t_off[1].x, t_off[1].y,
      t_off[1].z);
}

// --trace, at the end: per row of the model (v), the truth's mean y and z and the model's error.
void trace_rows(const sheet::SheetParams& sp, const SheetState& st,
                const std::vector<sheet::Vec3>& truth) {
  const int w = sp.grid.nodes_u, h = sp.grid.nodes_v;
  for (int j = 0; j < h; ++j) {
    sheet::Vec3 off, at;
    double e = 0;
    for (int i = 0; i < w; ++i) {
      const auto& p = truth[static_cast<std::size_t>(j * w + i)];
      const sheet::Vec3 d = node_off(st, j * w + i, p);
      off += d;
      at += p;
      e += sheet::norm(d);
    }
    std::printf("    row %2d: truth y %7.1f z %6.1f; error %6.2f mm, off %6.1f %6.1f %6.1f\n", j,
                at.y / w, at.z / w, e / w, off.x / w, off.y / w, off.z / w);
  }
}

}  // namespace

vision::SheetMesh mesh_of(const sheet::SheetParams& sp, const std::vector<sheet::Vec3>& nodes) {
  vision::SheetMesh m;
  m.nx = sp.grid.nodes_u;
  m.ny = sp.grid.nodes_v;
  m.w_mm = sp.grid.width_mm;
  m.h_mm = sp.grid.height_mm;
  for (const auto& p : nodes) m.nodes.emplace_back(p.x, p.y, p.z);
  return m;
}

SheetCreaseEvent half_fold_crease(const sheet::SheetParams& sp) {
  SheetCreaseEvent e;
  e.a_mm[0] = 0.0f;
  e.a_mm[1] = float(0.5 * sp.grid.height_mm);
  e.b_mm[0] = float(sp.grid.width_mm);
  e.b_mm[1] = float(0.5 * sp.grid.height_mm);
  return e;
}

double mean_error_mm(const SheetState& s, const std::vector<sheet::Vec3>& truth) {
  double e = 0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const auto& p = truth[k];
    e +=
        std::hypot(s.position_mm[k][0] - p.x, s.position_mm[k][1] - p.y, s.position_mm[k][2] - p.z);
  }
  return truth.empty() ? 0.0 : e / static_cast<double>(truth.size());
}

SceneFeed script_feed(const sheet::FoldScript& script, const sheet::SheetParams& sp,
                      double start_s) {
  return [&script, sp, start_s](double t_s, SceneAt& out) {
    out.truth.resize(static_cast<std::size_t>(sp.grid.nodes_u * sp.grid.nodes_v));
    script.node_positions(std::max(0.0, t_s - start_s), out.truth);
    out.mesh = mesh_of(sp, out.truth);
    out.shapes.clear();
  };
}

TrackingError track_sheet(const LoopSetup& s, bool use_depth, bool use_markers) {
  const std::string src = CREASE_SOURCE_DIR;
  const vision::MarkerLayout layout = vision::load_layout(src + "/config/markers/layout.yaml");
  const double ppm = s.printed ? 8.0 : 1.0;
  const cv::Mat front = s.printed ? vision::face_texture(layout, vision::Face::kFront, ppm)
                                  : vision::DepthSimSource::plain_texture(400, 400, ppm);
  const cv::Mat back = s.printed ? vision::face_texture(layout, vision::Face::kBack, ppm) : front;
  const auto colour_cams = vision::load_camera_dir(src + "/config/cameras");
  const vision::ViewRenderer renderer(front, back, ppm, colour_cams);
  vision::KeypointPipeline markers(colour_cams, layout, vision::DetectorConfig{},
                                   vision::TriangulationConfig{});
  use_markers = use_markers && s.printed;

  const sheet::SheetParams& sp = s.sheet;
  SceneAt scene;
  vision::RenderOptions ro;
  ro.noise_sigma = 1.0;
  vision::DepthColourModel colour;
  colour.plain = !s.printed;
  const auto depth_cams = vision::load_depth_camera_dir(src + "/config/depth_cameras");
  vision::DepthSimSource depth_source(
      depth_cams, front, back, ppm, [&](std::uint64_t) { return scene.mesh; }, ro,
      vision::DepthSensorModel{}, colour, 33'333'333);
  depth_source.set_shapes_source([&](std::vector<vision::SceneShape>& out) { out = scene.shapes; });
  depth::TrackerParams tp = s.depth;
  tp.cloud.mask = s.printed ? depth::HsvRange{0, 179, 0, 60, 150, 255}
                            // white paper: unsaturated, bright
                            : depth::HsvRange{95, 115, 120, 255, 40, 255};  // the blue paper
  depth::DepthTracker tracker;
  tracker.configure(tp, depth_cams);

  sheet::SheetRunner runner(sp, 0.0);
  auto state = std::make_unique<SheetState>();
  auto targets = std::make_unique<DepthTargets>();
  auto kp = std::make_unique<Keypoints>();
  auto robot = std::make_unique<TargetPoints>();
  std::int64_t now_ns = 1'000'000'000;
  (void)runner.step_rt(1.0 / 60, now_ns, *state);
  bool creased = false;
  TrackingError r;
  std::vector<double> err;
  vision::Frame f;
  std::vector<cv::Mat> depth_im(depth_cams.size()), bgr_im(depth_cams.size()),
      grey(colour_cams.size());
  vision::RenderedView view;
  long keypoints = 0, depth_targets = 0;
  const int frames = static_cast<int>(s.end_s * 30.0);
  for (int i = 0; i < frames; ++i) {
    const double t_now = i / 30.0;
    s.scene(t_now, scene);
    if (!creased && s.announce_crease && t_now >= s.crease_s) {
      runner.apply(half_fold_crease(sp));
      creased = true;
    }
    // Every frame while there are any (the sequence writes them every 10 ms), and once empty after.
    if (s.robot_targets && (!scene.robot_targets.empty() || robot->count > 0)) {
      robot->count = 0;
      for (const auto& p : scene.robot_targets)
        if (robot->count < TargetPoints::kCapacity) robot->points[robot->count++] = p;
      robot->timestamp_ns = now_ns;
      runner.set_targets(*robot);
    }
    if (use_depth) {
      (void)depth_source.grab(f);
      for (std::size_t k = 0; k < depth_cams.size(); ++k) {
        depth_im[k] = f.images[2 * k];
        bgr_im[k] = f.images[2 * k + 1];
      }
      (void)tracker.process(depth_im, bgr_im, *state, now_ns, static_cast<std::uint64_t>(i),
                            *targets);
      runner.set_depth_targets(*targets);
      ++r.depth_frames;
      depth_targets += targets->count;
    }
    if (use_markers && i % 2 == 0) {  // the vision loop's 15 Hz
      for (std::size_t k = 0; k < colour_cams.size(); ++k) {
        ro.seed = static_cast<std::uint64_t>(i + 1);
        renderer.render(static_cast<int>(k), scene.mesh, ro, view, scene.shapes);
        grey[k] = view.image.clone();
      }
      markers.process(grey, now_ns, *kp);
      kp->timestamp_ns = now_ns;
      runner.observe_keypoints(*kp);
      keypoints += kp->count;
      ++r.keypoint_sets;
    }
    for (int k = 0; k < 2; ++k) {
      now_ns += 16'666'667;
      (void)runner.step_rt(1.0 / 60, now_ns, *state);
    }
    if (t_now >= s.crease_s) {  // the model after this frame's steps against the truth then
      s.scene(t_now + 1.0 / 30, scene);
      err.push_back(mean_error_mm(*state, scene.truth));
      if (s.trace && i % 15 == 0)
        trace_frame(sp, t_now, err.back(), *state, scene.truth,
                    use_depth ? targets.get() : nullptr);
      if (err.back() >= r.worst_mm) {
        r.worst_mm = err.back();
        r.worst_s = t_now + 1.0 / 30;
      }
    }
  }
  if (s.trace && !err.empty()) trace_rows(sp, *state, scene.truth);
  for (double e : err) r.mean_mm += e / static_cast<double>(err.size());
  r.end_mm = err.empty() ? 0.0 : err.back();
  r.keypoints_mean = r.keypoint_sets > 0 ? static_cast<double>(keypoints) / r.keypoint_sets : 0.0;
  r.targets_mean = r.depth_frames > 0 ? static_cast<double>(depth_targets) / r.depth_frames : 0.0;
  return r;
}

}  // namespace crease::bench
