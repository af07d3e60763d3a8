#include "plugins/sim_world/scene/depth_sim_source.h"

#include <cmath>

#include "plugins/sim_world/scene/carried_camera.h"

namespace crease::vision {

DepthSimSource::DepthSimSource(std::vector<DepthCamera> cameras, const cv::Mat& front,
                               const cv::Mat& back, double ppm,
                               std::function<SheetMesh(std::uint64_t)> mesh_at,
                               RenderOptions render, DepthSensorModel sensor,
                               DepthColourModel colour, std::int64_t period_ns,
                               std::int64_t start_ns)
    : depth_cams_(std::move(cameras)),
      cams_(cameras_of(depth_cams_)),
      posed_(cams_),
      renderer_(front, back, ppm, cams_),
      mesh_at_(std::move(mesh_at)),
      render_(render),
      sensor_(sensor),
      colour_(colour),
      period_ns_(period_ns),
      start_ns_(start_ns) {
  render_.table_z_mm = sensor_.table_z_mm;  // the depth's table hides the shapes below it too
  render_.shape_lattice_px = 1;              // the shapes' depth exact: it is what the camera measures
  for (const Camera& c : cams_) rays_.push_back(ray_table(c));
  for (const DepthCamera& c : depth_cams_) any_carried_ = any_carried_ || c.mount.has_value();
}

cv::Mat DepthSimSource::plain_texture(double w_mm, double h_mm, double ppm) {
  return cv::Mat(static_cast<int>(std::ceil(h_mm * ppm)) + 1, static_cast<int>(std::ceil(w_mm * ppm)) + 1,
                 CV_8UC1, cv::Scalar(255));
}

bool DepthSimSource::grab(Frame& frame) {
  const SheetMesh mesh = mesh_at_(next_);
  if (shapes_now_) shapes_now_(shapes_);
  RenderOptions o = render_;
  o.seed = render_.seed + next_;
  frame.index = next_;
  frame.timestamp_ns = mesh.timestamp_ns >= 0 ? mesh.timestamp_ns
                                              : start_ns_ + static_cast<std::int64_t>(next_) * period_ns_;
  frame.images.resize(2 * cams_.size());
  if (any_carried_) frame.poses.assign(2 * cams_.size(), crease::frames::CameraPose{});
  for (std::size_t k = 0; k < cams_.size(); ++k) {
    cv::Mat& depth = frame.images[2 * k];
    cv::Mat& bgr = frame.images[2 * k + 1];
    if (const auto& mount = depth_cams_[k].mount) {
      carried_frames_.fetch_add(1, std::memory_order_relaxed);
      if (!place_carried_camera(cams_[k], *mount, shapes_, posed_[k])) {
        depth = cv::Mat();  // nothing delivered: the channel marks the camera invalid
        bgr = cv::Mat();
        carried_unposed_.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      renderer_.set_pose(static_cast<int>(k), posed_[k].R, posed_[k].t);
      frame.poses[2 * k] = frame.poses[2 * k + 1] = carried_pose(posed_[k].R, posed_[k].t);
    }
    renderer_.render(static_cast<int>(k), mesh, o, view_, shapes_);
    if (!frame.fill_in_place) {  // fresh buffers: the caller keeps the last ones
      depth = cv::Mat();
      bgr = cv::Mat();
    }
    make_depth_view(posed_[k], rays_[k], depth_cams_[k].depth_unit_mm, view_, sensor_, colour_,
                    o.seed * 31 + k, depth, bgr);
  }
  ++next_;
  return true;
}

}  // namespace crease::vision
