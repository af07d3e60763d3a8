// One depth frame set through the depth path (seed 001 Sec. III-B, issue 17): colour mask and
// valid depth -> world cloud of every camera that delivered (point_cloud.h), voxel-downsampled;
// the model nodes some camera sees (visibility.h: the model's own layers z-buffered, and no
// measured surface more than occluder_mm in front of the node) as CPD's active centroids,
// registered onto the cloud (sheet_cpd.h, warm start from the model's newest state); then one
// target per active node with posterior support P1 >= min_support and no hidden node within
// occlusion_margin grid steps (next to a hidden part a node's points all lie on the seen side, and
// CPD moves it there: such targets dragged an occluded lower layer towards its part still seen):
// the registered position, weight min(1, P1 / full_support). The sheet model pulls each along its
// normal (DepthTargets, sheet_model). No threads here (depth_worker.h runs it on one); configure()
// allocates, process() does not.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "core/frames/frame_channel.h"
#include "core/params.h"
#include "core/port_types/depth_targets.h"
#include "core/port_types/sheet_state.h"
#include "plugins/camera_rig/depth_camera.h"
#include "plugins/depth_tracking/point_cloud.h"
#include "plugins/depth_tracking/sheet_cpd.h"
#include "plugins/depth_tracking/visibility.h"

namespace crease::depth {

struct TrackerParams {
  CloudParams cloud;
  CpdParams cpd;
  int max_points = 20000;       // cloud points CPD takes (more: thinned by a stride)
  int kernel_rank = 60;         // sheet kernel rank at most
  double kernel_cut = 20.0;     // E-step: kernel values below exp(-kernel_cut) are zero
  double min_support = 0.5;     // P1 a node needs for a target (expected points it explains)
  double full_support = 4.0;    // P1 of a weight-1 target
  int visibility_scale = 4;     // the visibility buffers' resolution divisor
  int visibility_cells = 1;      // a node's pixels may show cells this many steps from its own
  double occluder_mm = 10.0;    // a measured surface this much nearer than a node hides it (0: off)
  int occlusion_margin = 1;     // no target within this many grid steps of a hidden node
  bool use_visibility = true;   // false: every node is a centroid (the baseline's layer mix-up)
  int nodes_u = 15, nodes_v = 21;
  double width_mm = 210.0, height_mm = 297.0;
};

// Plugin parameters (keys: mask {h_lo h_hi s_lo s_hi v_lo v_hi}, voxel_mm, min_depth_mm,
// max_depth_mm, max_points, cpd {cpd_params.h's keys}, kernel_rank, kernel_cut, min_support,
// full_support, visibility_scale, visibility_cells, occluder_mm, occlusion_margin, visibility,
// nodes_u, nodes_v, width_mm, height_mm); every range error a ConfigError naming file, line and
// key.
TrackerParams tracker_params_from(const crease::Params& p);

struct FrameTiming {
  std::int64_t cloud_ns = 0;  // mask, back-projection, voxels
  std::int64_t cpd_ns = 0;    // visibility and registration
};

class DepthTracker {
 public:
  // Non-RT. cameras: the depth calibrations (their depth units override params.cloud's).
  void configure(const TrackerParams& params, const std::vector<vision::DepthCamera>& cameras);

  // depth[k], bgr[k]: camera k's images (empty Mats: nothing from it); model: the sheet model's
  // newest state (its grid must be the configured one); poses[k]: where camera k was at this
  // capture (core/frames/frame_channel.h; missing or not `carried`: a fixed camera, its
  // calibration). A carried camera's view goes into the world, and its visibility is checked,
  // from its frame's pose; a view whose pose is unusable (not finite, no rotation; or a camera
  // calibrated as carried, camera_mount.h, whose frame came without a pose) is dropped and
  // counted (bad_pose_views), as a camera that delivered nothing. Fills `out` (count 0 and false
  // when nothing could be registered: no model, no cloud, a wrong grid). No allocation.
  bool process(std::span<const cv::Mat> depth, std::span<const cv::Mat> bgr,
               const SheetState& model, std::int64_t stamp_ns, std::uint64_t frame,
               DepthTargets& out, std::span<const frames::CameraPose> poses = {}) noexcept;

  // Camera views delivered (images present) and of those dropped for a bad pose, since configure.
  [[nodiscard]] std::uint64_t views() const noexcept { return views_; }
  [[nodiscard]] std::uint64_t bad_pose_views() const noexcept { return bad_pose_views_; }
  // Bit k: camera k's view of the last process() was dropped for its pose.
  [[nodiscard]] std::uint32_t last_bad_pose_mask() const noexcept { return bad_pose_mask_; }

  [[nodiscard]] const FrameTiming& timing() const noexcept { return timing_; }
  [[nodiscard]] const CloudBuilder& cloud() const noexcept { return cloud_; }
  [[nodiscard]] const CpdResult& last_cpd() const noexcept { return last_; }
  [[nodiscard]] std::span<const std::uint8_t> active() const noexcept { return active_; }
  [[nodiscard]] std::span<const Eigen::Vector3d> registered() const noexcept { return out_; }
  [[nodiscard]] const TrackerParams& params() const noexcept { return params_; }

 private:
  void mark_hidden_margin() noexcept;  // near_hidden_ from active_; no allocation

  TrackerParams params_;
  CloudBuilder cloud_;
  SheetCpd cpd_;
  NodeVisibility vis_;
  std::vector<Eigen::Vector2d> uv_;
  std::vector<Eigen::Vector3d> nodes_, out_;
  std::vector<double> support_;
  std::vector<std::uint32_t> seen_;
  std::vector<std::uint8_t> active_;
  std::vector<std::uint8_t> near_hidden_;  // per node: within occlusion_margin of a hidden node
  CpdResult last_;
  FrameTiming timing_;
  std::vector<vision::Camera> cams_;   // the calibrations (a fixed camera's pose)
  std::vector<std::uint8_t> carried_;  // per camera: calibrated on a mount (needs a frame pose)
  std::uint64_t views_ = 0, bad_pose_views_ = 0;
  std::uint32_t bad_pose_mask_ = 0;
};

}  // namespace crease::depth
