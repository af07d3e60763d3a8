#include "plugins/depth_tracking/depth_tracker.h"

#include <algorithm>
#include <cmath>

#include "plugins/camera_rig/camera_mount.h"
#include "plugins/depth_tracking/cpd_params.h"
#include "rt/clock.h"

namespace crease::depth {

TrackerParams tracker_params_from(const crease::Params& p) {
  TrackerParams t;
  const crease::Params m = p.child("mask");
  HsvRange& r = t.cloud.mask;
  r.h_lo = m.get_in_range<int>("h_lo", r.h_lo, 0, 179);
  r.h_hi = m.get_in_range<int>("h_hi", r.h_hi, 0, 179);
  r.s_lo = m.get_in_range<int>("s_lo", r.s_lo, 0, 255);
  r.s_hi = m.get_in_range<int>("s_hi", r.s_hi, r.s_lo, 255);
  r.v_lo = m.get_in_range<int>("v_lo", r.v_lo, 0, 255);
  r.v_hi = m.get_in_range<int>("v_hi", r.v_hi, r.v_lo, 255);
  t.cloud.voxel_mm = p.get_in_range<double>("voxel_mm", 6.0, 0.1, 1000.0);
  t.cloud.min_depth_mm = p.get_in_range<double>("min_depth_mm", t.cloud.min_depth_mm, 0.0, 1e5);
  t.cloud.max_depth_mm = p.get_in_range<double>("max_depth_mm", t.cloud.max_depth_mm, t.cloud.min_depth_mm + 1e-3, 1e5);
  t.max_points = p.get_in_range<int>("max_points", t.max_points, 1, 10000000);
  t.cpd = cpd_params_from(p.child("cpd"));
  t.kernel_rank = p.get_in_range<int>("kernel_rank", t.kernel_rank, 1, 4096);
  t.kernel_cut = p.get_in_range<double>("kernel_cut", t.kernel_cut, 4.0, 700.0);
  t.min_support = p.get_in_range<double>("min_support", t.min_support, 0.0, 1e6);
  t.full_support = p.get_in_range<double>("full_support", t.full_support, 1e-6, 1e6);
  t.visibility_scale = p.get_in_range<int>("visibility_scale", t.visibility_scale, 1, 64);
  t.visibility_cells = p.get_in_range<int>("visibility_cells", t.visibility_cells, 0, 64);
  t.occluder_mm = p.get_in_range<double>("occluder_mm", t.occluder_mm, 0.0, 1e4);
  t.occlusion_margin = p.get_in_range<int>("occlusion_margin", t.occlusion_margin, 0, 64);
  t.use_visibility = p.get<bool>("visibility", true);
  t.nodes_u = p.get_in_range<int>("nodes_u", t.nodes_u, 2, 64);
  t.nodes_v = p.get_in_range<int>("nodes_v", t.nodes_v, 2, 64);
  t.width_mm = p.get_in_range<double>("width_mm", t.width_mm, 10.0, 2000.0);
  t.height_mm = p.get_in_range<double>("height_mm", t.height_mm, 10.0, 2000.0);
  return t;
}

void DepthTracker::configure(const TrackerParams& p, const std::vector<vision::DepthCamera>& cameras) {
  params_ = p;
  CloudParams cp = p.cloud;
  cp.camera_depth_unit_mm.clear();
  for (const auto& c : cameras) cp.camera_depth_unit_mm.push_back(c.depth_unit_mm);
  const std::vector<vision::Camera> cams = vision::cameras_of(cameras);
  cams_ = cams;
  carried_.clear();
  for (const auto& c : cameras) carried_.push_back(c.mount ? 1 : 0);
  views_ = bad_pose_views_ = 0;
  bad_pose_mask_ = 0;
  std::size_t pixels = 0;
  for (const auto& c : cams) pixels += static_cast<std::size_t>(c.width) * static_cast<std::size_t>(c.height);
  cloud_.configure(cp, cams, static_cast<int>(std::min<std::size_t>(pixels, 50000000)));
  const int n = p.nodes_u * p.nodes_v;
  uv_.resize(static_cast<std::size_t>(n));
  for (int j = 0; j < p.nodes_v; ++j)
    for (int i = 0; i < p.nodes_u; ++i)
      uv_[static_cast<std::size_t>(j * p.nodes_u + i)] =
          Eigen::Vector2d(i * p.width_mm / (p.nodes_u - 1), j * p.height_mm / (p.nodes_v - 1));
  cpd_.configure(p.cpd, uv_, p.max_points, p.kernel_rank, 1e-7, p.kernel_cut);
  vis_.configure(cams, p.nodes_u, p.nodes_v, p.visibility_scale, p.visibility_cells);
  vis_.set_depth_check(cp.camera_depth_unit_mm, p.occluder_mm);
  nodes_.assign(static_cast<std::size_t>(n), Eigen::Vector3d::Zero());
  out_ = nodes_;
  support_.assign(static_cast<std::size_t>(n), 0.0);
  seen_.assign(static_cast<std::size_t>(n), 0u);
  active_.assign(static_cast<std::size_t>(n), 0);
  near_hidden_.assign(static_cast<std::size_t>(n), 0);
}

void DepthTracker::mark_hidden_margin() noexcept {
  const int nu = params_.nodes_u, nv = params_.nodes_v, m = params_.occlusion_margin;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      bool near = false;
      for (int b = std::max(0, j - m); b <= std::min(nv - 1, j + m) && !near; ++b)
        for (int a = std::max(0, i - m); a <= std::min(nu - 1, i + m) && !near; ++a)
          near = active_[static_cast<std::size_t>(b * nu + a)] == 0;
      near_hidden_[static_cast<std::size_t>(j * nu + i)] = near ? 1 : 0;
    }
}

bool DepthTracker::process(std::span<const cv::Mat> depth, std::span<const cv::Mat> bgr,
                           const SheetState& model, std::int64_t stamp_ns, std::uint64_t frame,
                           DepthTargets& out, std::span<const frames::CameraPose> poses) noexcept {
  out.timestamp_ns = stamp_ns;
  out.frame = frame;
  out.count = 0;
  out.cloud_points = 0;
  out.visible_nodes = 0;
  out.iterations = 0;
  out.sigma2_mm2 = 0;
  out.cameras_ok = 0;
  const std::int64_t t0 = crease::rt::now_ns();
  cloud_.clear();
  const std::size_t ncam = std::min({depth.size(), bgr.size(), cams_.size()});
  bad_pose_mask_ = 0;
  for (std::size_t k = 0; k < ncam; ++k) {
    if (depth[k].empty() || bgr[k].empty()) continue;
    ++views_;
    // Where the camera was at this capture: its frame's pose when it moves, else its calibration.
    cv::Matx33d R = cams_[k].R;
    cv::Vec3d t = cams_[k].t;
    const bool posed = k < poses.size() && poses[k].carried;
    if ((posed || carried_[k] != 0) && !(posed && vision::camera_from_pose(poses[k], R, t))) {
      ++bad_pose_views_;
      bad_pose_mask_ |= 1u << k;
      continue;  // dropped: as if the camera delivered nothing
    }
    (void)vis_.set_pose(k, R, t);
    if (cloud_.add_view(static_cast<int>(k), depth[k], bgr[k], R, t)) out.cameras_ok |= 1u << k;
  }
  cloud_.voxel_downsample();
  const std::int64_t t1 = crease::rt::now_ns();
  timing_.cloud_ns = t1 - t0;
  timing_.cpd_ns = 0;
  last_ = CpdResult{};
  const int n = params_.nodes_u * params_.nodes_v;
  if (model.nodes_u != params_.nodes_u || model.nodes_v != params_.nodes_v || cloud_.points().empty()) return false;
  for (int i = 0; i < n; ++i)
    nodes_[static_cast<std::size_t>(i)] =
        Eigen::Vector3d(model.position_mm[i][0], model.position_mm[i][1], model.position_mm[i][2]);
  int visible = 0;
  if (params_.use_visibility) {
    (void)vis_.compute(nodes_, out.cameras_ok, seen_, depth.first(ncam));
    for (int i = 0; i < n; ++i) visible += (active_[static_cast<std::size_t>(i)] = seen_[static_cast<std::size_t>(i)] != 0 ? 1 : 0);
  } else {
    std::fill(active_.begin(), active_.end(), std::uint8_t{1});
    visible = n;
  }
  out.visible_nodes = static_cast<std::uint32_t>(visible);
  last_ = cpd_.register_cloud(nodes_, active_, cloud_.points(), out_, support_);
  timing_.cpd_ns = crease::rt::now_ns() - t1;
  out.cloud_points = static_cast<std::uint32_t>(last_.points_used);
  out.iterations = static_cast<std::uint32_t>(last_.iterations);
  out.sigma2_mm2 = static_cast<float>(last_.sigma2_mm2);
  if (!last_.ok) return false;
  mark_hidden_margin();
  for (int i = 0; i < n && out.count < DepthTargets::kCapacity; ++i) {
    const auto s = static_cast<std::size_t>(i);
    if (!active_[s] || near_hidden_[s] || !(support_[s] >= params_.min_support) ||
        !(support_[s] > 0.0))
      continue;
    DepthTargets::Point& p = out.points[out.count++];
    for (int c = 0; c < 3; ++c) p.world_mm[c] = static_cast<float>(out_[s][c]);
    p.sheet_mm[0] = static_cast<float>(uv_[s][0]);
    p.sheet_mm[1] = static_cast<float>(uv_[s][1]);
    p.weight = static_cast<float>(std::min(1.0, support_[s] / params_.full_support));
  }
  return true;
}

}  // namespace crease::depth
