#include "plugins/sim_world/scene/depth_view.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace crease::vision {

double depth_sigma_mm(const DepthSensorModel& m, double f_px, double z_mm) noexcept {
  return z_mm * z_mm * m.subpixel / (f_px * m.baseline_mm);
}

cv::Mat ray_table(const Camera& cam) {
  cv::Mat rays(cam.height, cam.width, CV_32FC2);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const cv::Point2d n = cam.undistort({double(x), double(y)});
      rays.at<cv::Vec2f>(y, x) = cv::Vec2f(float(n.x), float(n.y));
    }
  return rays;
}

void make_depth_view(const Camera& cam, const cv::Mat& rays, double unit_mm, const RenderedView& view,
                     const DepthSensorModel& sm, const DepthColourModel& cm, std::uint64_t seed,
                     cv::Mat& depth, cv::Mat& bgr) {
  const int W = cam.width, H = cam.height;
  depth.create(H, W, CV_16UC1);
  bgr.create(H, W, CV_8UC3);
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // True camera-frame z of what each pixel sees: a world shape, else the sheet, else the table
  // (raised by a random occluder).
  cv::Mat z(H, W, CV_32F);
  const cv::Vec3d c = cam.centre_world();
  const cv::Matx33d rt = cam.R.t();
  for (int y = 0; y < H; ++y) {
    const auto* ray = rays.ptr<cv::Vec2f>(y);
    const float* zs = view.depth.ptr<float>(y);
    const std::uint8_t* occ = view.occluder_mask.empty() ? nullptr : view.occluder_mask.ptr<std::uint8_t>(y);
    const float* zh = view.shape_depth.empty() ? nullptr : view.shape_depth.ptr<float>(y);
    const std::uint8_t* grey = view.image.ptr<std::uint8_t>(y);
    float* zr = z.ptr<float>(y);
    auto* col = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < W; ++x) {
      // Table: world z = table_z along the ray c + s * R^T (x, y, 1) (s is the camera z).
      const cv::Vec3d d = rt * cv::Vec3d(ray[x][0], ray[x][1], 1.0);
      const double s_table = std::abs(d[2]) > 1e-12 ? (sm.table_z_mm - c[2]) / d[2] : -1.0;
      const bool sheet = std::isfinite(zs[x]) && (s_table <= 0 || zs[x] <= s_table);
      double zz = sheet ? zs[x] : (s_table > 0 ? s_table : kInf);
      const bool shape =
          zh != nullptr && std::isfinite(zh[x]);  // the world's arms and hands: exact
      const bool hand = shape || (occ != nullptr && occ[x] != 0);
      const double g = grey[x];
      if (hand) {
        zz = shape ? zh[x] : zz - sm.hand_height_mm;
        const double shade = std::min(1.0, g / 170.0);
        col[x] = cv::Vec3b(cv::saturate_cast<std::uint8_t>(cm.hand_bgr[0] * shade),
                           cv::saturate_cast<std::uint8_t>(cm.hand_bgr[1] * shade),
                           cv::saturate_cast<std::uint8_t>(cm.hand_bgr[2] * shade));
      } else if (sheet && cm.plain) {
        const double shade = g / 225.0;  // the renderer's white paper albedo, shaded and noisy
        col[x] = cv::Vec3b(cv::saturate_cast<std::uint8_t>(cm.sheet_bgr[0] * shade),
                           cv::saturate_cast<std::uint8_t>(cm.sheet_bgr[1] * shade),
                           cv::saturate_cast<std::uint8_t>(cm.sheet_bgr[2] * shade));
      } else {
        col[x] = cv::Vec3b(grey[x], grey[x], grey[x]);
      }
      zr[x] = static_cast<float>(zz);
    }
  }
  cv::RNG rng(seed * 2862933555777941757ULL + 3037000493ULL);
  const double f = cam.mean_focal_px();
  const double cos_max = std::cos(sm.max_incidence_deg * CV_PI / 180.0);
  const auto point = [&](int x, int y) {
    const cv::Vec2f r = rays.at<cv::Vec2f>(y, x);
    const double zz = z.at<float>(y, x);
    return cv::Vec3d(r[0] * zz, r[1] * zz, zz);
  };
  for (int y = 0; y < H; ++y) {
    const float* zr = z.ptr<float>(y);
    auto* out = depth.ptr<std::uint16_t>(y);
    for (int x = 0; x < W; ++x) {
      out[x] = 0;
      const double zz = zr[x];
      if (!std::isfinite(zz) || zz < sm.min_range_mm || zz > sm.max_range_mm) continue;
      if (x == 0 || y == 0 || x + 1 == W || y + 1 == H) continue;  // no neighbours: no match
      const float zl = zr[x - 1], zrr = zr[x + 1], zu = z.at<float>(y - 1, x), zd = z.at<float>(y + 1, x);
      if (!(std::abs(zl - zz) <= sm.edge_jump_mm && std::abs(zrr - zz) <= sm.edge_jump_mm &&
            std::abs(zu - zz) <= sm.edge_jump_mm && std::abs(zd - zz) <= sm.edge_jump_mm))
        continue;  // a depth edge (also: a neighbour sees nothing)
      const cv::Vec3d p = point(x, y);
      const cv::Vec3d n = (point(x + 1, y) - point(x - 1, y)).cross(point(x, y + 1) - point(x, y - 1));
      const double nn = cv::norm(n), pn = cv::norm(p);
      if (!(nn > 0) || std::abs(n.dot(p)) < cos_max * nn * pn) continue;  // grazing
      const double noisy = sm.noise ? zz + rng.gaussian(depth_sigma_mm(sm, f, zz)) : zz;
      const double counts = std::round(noisy / unit_mm);
      if (counts >= 1 && counts <= 65535) out[x] = static_cast<std::uint16_t>(counts);
    }
  }
}

}  // namespace crease::vision
