#include "plugins/sim_world/scene/synthetic_truth.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace crease::vision {

std::vector<VisibleMarker> visible_markers(const Camera& cam, const SheetMesh& mesh, const MarkerLayout& layout,
                                           const RenderedView& view, double min_side_px, double min_cos) {
  std::vector<VisibleMarker> out;
  const cv::Rect frame(0, 0, cam.width, cam.height);
  for (const auto& m : layout.markers) {
    const cv::Vec3d c = mesh.world_at(m.centre_mm.x, m.centre_mm.y);
    const cv::Vec3d n = mesh.front_normal_at(m.centre_mm.x, m.centre_mm.y) * (m.face == Face::kFront ? 1.0 : -1.0);
    if (n.dot(cv::normalize(cam.centre_world() - c)) < min_cos) continue;
    // A tag bent by a fold is not a tag any more: all corners must share the centre's normal.
    bool flat = true;
    for (const auto& uv : m.corners_mm) flat = flat && mesh.front_normal_at(uv.x, uv.y).dot(
        mesh.front_normal_at(m.centre_mm.x, m.centre_mm.y)) > 0.995;
    if (!flat) continue;
    VisibleMarker v;
    v.id = m.id;
    bool inside = true;
    for (int q = 0; q < 4; ++q) {
      const auto& uv = m.corners_mm[static_cast<std::size_t>(q)];
      cv::Point2d& p = v.corners_px[static_cast<std::size_t>(q)];
      inside = inside && cam.project(mesh.world_at(uv.x, uv.y), p) && p.x > 8 && p.y > 8 &&
               p.x < cam.width - 9 && p.y < cam.height - 9;
    }
    if (!inside) continue;
    v.min_side_px = 1e9;
    for (int q = 0; q < 4; ++q)
      v.min_side_px = std::min(v.min_side_px, cv::norm(v.corners_px[static_cast<std::size_t>((q + 1) % 4)] -
                                                       v.corners_px[static_cast<std::size_t>(q)]));
    if (v.min_side_px < min_side_px) continue;
    std::vector<cv::Point> poly;
    for (const auto& p : v.corners_px) poly.emplace_back(cvRound(p.x), cvRound(p.y));
    const cv::Rect box = (cv::boundingRect(poly) + cv::Size(16, 16) - cv::Point(8, 8)) & frame;
    if (!view.occluder_mask.empty() && cv::countNonZero(view.occluder_mask(box)) > 0) continue;
    // Another part of the sheet in front: compare rendered depth with the tag's at 5 points.
    bool hidden = false;
    cv::Point2d cp;
    cam.project(c, cp);
    std::array<cv::Point2d, 5> probes = {cp, v.corners_px[0], v.corners_px[1], v.corners_px[2], v.corners_px[3]};
    std::array<cv::Vec3d, 5> worlds = {c, mesh.world_at(m.corners_mm[0].x, m.corners_mm[0].y),
                                       mesh.world_at(m.corners_mm[1].x, m.corners_mm[1].y),
                                       mesh.world_at(m.corners_mm[2].x, m.corners_mm[2].y),
                                       mesh.world_at(m.corners_mm[3].x, m.corners_mm[3].y)};
    for (int q = 0; q < 5 && !hidden; ++q) {
      // Pull corner probes slightly towards the centre to stay on the tag.
      const cv::Point2d p = q == 0 ? probes[0] : probes[static_cast<std::size_t>(q)] * 0.9 + cp * 0.1;
      const cv::Vec3d w = q == 0 ? worlds[0] : worlds[static_cast<std::size_t>(q)] * 0.9 + c * 0.1;
      const float d = view.depth.at<float>(cvRound(p.y), cvRound(p.x));
      hidden = std::abs(d - cam.to_camera(w)[2]) > 1.5;
    }
    if (hidden) continue;
    out.push_back(v);
  }
  return out;
}

}  // namespace crease::vision
