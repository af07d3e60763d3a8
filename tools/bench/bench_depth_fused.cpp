// The printed sheet tracked by the markers alone and by the markers with the depth path
// (bench_depth_fused.h). The depth cameras' colour image of the printed sheet is its grey print
// (camera_depth_sim's `sheet: markers`): the mask keeps the bright paper, not the mid-grey
// table or the black markers (holes in the cloud, filled by the voxels around them).
#include "tools/bench/bench_depth_fused.h"

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

TrackingError track_printed_sheet(const FusedSetup& s, bool use_depth, bool use_markers) {
  const std::string src = CREASE_SOURCE_DIR;
  const vision::MarkerLayout layout = vision::load_layout(src + "/config/markers/layout.yaml");
  const double ppm = 8.0;
  const cv::Mat front = vision::face_texture(layout, vision::Face::kFront, ppm);
  const cv::Mat back = vision::face_texture(layout, vision::Face::kBack, ppm);
  const auto colour_cams = vision::load_camera_dir(src + "/config/cameras");
  const vision::ViewRenderer renderer(front, back, ppm, colour_cams);
  vision::KeypointPipeline markers(colour_cams, layout, vision::DetectorConfig{},
                                   vision::TriangulationConfig{});

  const sheet::SheetParams& sp = s.sheet;
  std::vector<sheet::Vec3> truth(static_cast<std::size_t>(sp.grid.nodes_u * sp.grid.nodes_v));
  double t_now = 0.0;
  const auto mesh_now = [&] {
    s.script->node_positions(std::max(0.0, t_now - s.start_s), truth);
    return mesh_of(sp, truth);
  };
  vision::RenderOptions ro;
  ro.noise_sigma = 1.0;
  vision::DepthColourModel colour;
  colour.plain = false;
  const auto depth_cams = vision::load_depth_camera_dir(src + "/config/depth_cameras");
  vision::DepthSimSource depth_source(
      depth_cams, front, back, ppm, [&](std::uint64_t) { return mesh_now(); }, ro,
      vision::DepthSensorModel{}, colour, 33'333'333);
  depth::TrackerParams tp = s.depth;
  tp.cloud.mask = {0, 179, 0, 60, 150, 255};  // white paper: unsaturated, bright
  depth::DepthTracker tracker;
  tracker.configure(tp, depth_cams);

  sheet::SheetRunner runner(sp, 0.0);
  auto state = std::make_unique<SheetState>();
  auto targets = std::make_unique<DepthTargets>();
  auto kp = std::make_unique<Keypoints>();
  std::int64_t now_ns = 1'000'000'000;
  (void)runner.step_rt(1.0 / 60, now_ns, *state);
  bool creased = false;
  TrackingError r;
  std::vector<double> err;
  vision::Frame f;
  std::vector<cv::Mat> depth_im(depth_cams.size()), bgr_im(depth_cams.size()),
      grey(colour_cams.size());
  vision::RenderedView view;
  long keypoints = 0;
  const int frames = static_cast<int>(s.end_s * 30.0);
  for (int i = 0; i < frames; ++i) {
    t_now = i / 30.0;
    if (!creased && t_now >= s.start_s) {
      runner.apply(half_fold_crease(sp));
      creased = true;
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
    }
    if (use_markers && i % 2 == 0) {  // the vision loop's 15 Hz
      const vision::SheetMesh mesh = mesh_now();
      for (std::size_t k = 0; k < colour_cams.size(); ++k) {
        ro.seed = static_cast<std::uint64_t>(i + 1);
        renderer.render(static_cast<int>(k), mesh, ro, view);
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
    if (t_now >= s.start_s) {
      s.script->node_positions(std::max(0.0, t_now + 1.0 / 30 - s.start_s), truth);
      err.push_back(mean_error_mm(*state, truth));
    }
  }
  for (double e : err) r.mean_mm += e / static_cast<double>(err.size());
  r.worst_mm = err.empty() ? 0.0 : *std::max_element(err.begin(), err.end());
  r.end_mm = err.empty() ? 0.0 : err.back();
  r.keypoints_mean = r.keypoint_sets > 0 ? static_cast<double>(keypoints) / r.keypoint_sets : 0.0;
  return r;
}

}  // namespace crease::bench
