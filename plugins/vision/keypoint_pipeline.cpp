#include "plugins/vision/keypoint_pipeline.h"

#include <cmath>
#include <string>

#include "core/assert.h"

namespace crease::vision {

cv::Point2d tag_centre_normalized(const Camera& cam, const std::array<cv::Point2f, 4>& c) {
  cv::Point2d n[4];
  for (int k = 0; k < 4; ++k) n[k] = cam.undistort(cv::Point2d(c[k]));
  // Lines 0-2 and 1-3 in homogeneous form.
  const cv::Vec3d l1 = cv::Vec3d(n[0].x, n[0].y, 1).cross(cv::Vec3d(n[2].x, n[2].y, 1));
  const cv::Vec3d l2 = cv::Vec3d(n[1].x, n[1].y, 1).cross(cv::Vec3d(n[3].x, n[3].y, 1));
  const cv::Vec3d x = l1.cross(l2);
  if (std::abs(x[2]) < 1e-15) return 0.25 * (n[0] + n[1] + n[2] + n[3]);
  return {x[0] / x[2], x[1] / x[2]};
}

void build_keypoints(const std::vector<Camera>& cams, const MarkerLayout& layout,
                     const std::vector<std::vector<MarkerDetection>>& dets, const TriangulationConfig& tri,
                     crease::Keypoints& out) {
  out.count = 0;
  const int ncam = static_cast<int>(std::min<std::size_t>(cams.size(), kMaxViews));
  // Detections are sorted by id per camera: walk them together, one marker id at a time.
  std::vector<std::size_t> pos(static_cast<std::size_t>(ncam), 0);
  for (;;) {
    int id = -1;
    for (int k = 0; k < ncam; ++k) {
      const auto& d = dets[static_cast<std::size_t>(k)];
      if (pos[static_cast<std::size_t>(k)] < d.size()) {
        const int i = d[pos[static_cast<std::size_t>(k)]].id;
        if (id < 0 || i < id) id = i;
      }
    }
    if (id < 0) break;
    const MarkerDetection* seen[kMaxViews];
    int cam_of[kMaxViews];
    int nv = 0;
    for (int k = 0; k < ncam; ++k) {
      const auto& d = dets[static_cast<std::size_t>(k)];
      auto& p = pos[static_cast<std::size_t>(k)];
      if (p < d.size() && d[p].id == id) {
        seen[nv] = &d[p];
        cam_of[nv++] = k;
        ++p;
      }
    }
    const int li = layout.index_of(id);
    if (nv < 2 || li < 0) continue;
    const MarkerPlacement& mp = layout.markers[static_cast<std::size_t>(li)];
    for (int kp = 0; kp < 5; ++kp) {
      if (out.count >= crease::Keypoints::kCapacity) return;
      ViewObservation obs[kMaxViews];
      for (int v = 0; v < nv; ++v) {
        const Camera& cam = cams[static_cast<std::size_t>(cam_of[v])];
        obs[v].camera = cam_of[v];
        obs[v].normalized = kp == 0 ? tag_centre_normalized(cam, seen[v]->corners)
                                    : cam.undistort(cv::Point2d(seen[v]->corners[kp - 1]));
      }
      TriangulatedPoint tp;
      if (!triangulate(cams.data(), obs, nv, tri, tp)) continue;
      crease::Keypoint& k = out.points[out.count++];
      for (int a = 0; a < 3; ++a) k.world_mm[a] = static_cast<float>(tp.world_mm[a]);
      const cv::Point2d uv = kp == 0 ? mp.centre_mm : mp.corners_mm[static_cast<std::size_t>(kp - 1)];
      k.sheet_mm[0] = static_cast<float>(uv.x);
      k.sheet_mm[1] = static_cast<float>(uv.y);
      k.reproj_error_px = static_cast<float>(tp.rms_px);
      k.marker_id = static_cast<std::uint16_t>(id);
      k.corner = static_cast<std::uint8_t>(kp);
      k.face = static_cast<std::uint8_t>(mp.face);
      k.views = tp.views;
    }
  }
}

KeypointPipeline::KeypointPipeline(std::vector<Camera> cams, MarkerLayout layout, DetectorConfig det,
                                   TriangulationConfig tri, int camera_threads)
    : cams_(std::move(cams)), layout_(std::move(layout)), tri_(tri) {
  // The vision plugin reads camera_threads in [0, 64]: a negative count is a caller's bug.
  CREASE_DEMAND(camera_threads >= 0, "camera_threads: expected 0 (OpenCV's pool) or >= 1");
  if (camera_threads >= 1) team_ = std::make_unique<TaskTeam>(camera_threads - 1);
  if (det.max_id < 0) det.max_id = layout_.max_id();
  det.dictionary = layout_.dictionary;
  for (std::size_t k = 0; k < cams_.size(); ++k) detectors_.emplace_back(det);
  dets_.resize(cams_.size());
}

void KeypointPipeline::reset() {
  for (auto& d : detectors_) d.reset();
}

void KeypointPipeline::process(const std::vector<cv::Mat>& images, std::int64_t t_ns, crease::Keypoints& out) {
  const int n = static_cast<int>(cams_.size());
  // Camera k touches only detectors_[k] and dets_[k].
  const auto detect = [&](int k) {
    const auto ku = static_cast<std::size_t>(k);
    if (ku < images.size() && !images[ku].empty())
      detectors_[ku].detect(images[ku], dets_[ku]);
    else
      dets_[ku].clear();
  };
  if (team_) {
    team_->run(n, detect);
  } else {
    cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& r) {
      for (int k = r.start; k < r.end; ++k) detect(k);
    }, n);
  }
  out.timestamp_ns = t_ns;
  out.frame = frame_++;
  out.cameras_ok = 0;
  for (int k = 0; k < n && k < 32; ++k)
    if (static_cast<std::size_t>(k) < images.size() && !images[static_cast<std::size_t>(k)].empty())
      out.cameras_ok |= 1u << k;
  build_keypoints(cams_, layout_, dets_, tri_, out);
}

}  // namespace crease::vision
