#include "plugins/depth_tracking/point_cloud.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"

namespace crease::depth {
namespace {

void check(bool ok, const char* key, const std::string& reason) {
  if (!ok) throw ConfigError(std::string("depth_tracking: ") + key + ": " + reason);
}

}  // namespace

void bgr_to_hsv(std::uint8_t b, std::uint8_t g, std::uint8_t r, int& h, int& s, int& v) noexcept {
  const int mx = std::max({b, g, r});
  const int mn = std::min({b, g, r});
  const int d = mx - mn;
  v = mx;
  s = mx == 0 ? 0 : (d * 255 + mx / 2) / mx;
  if (d == 0) {
    h = 0;
    return;
  }
  double hd;  // degrees
  if (mx == r) {
    hd = 60.0 * (g - b) / d;
  } else if (mx == g) {
    hd = 120.0 + 60.0 * (b - r) / d;
  } else {
    hd = 240.0 + 60.0 * (r - g) / d;
  }
  if (hd < 0.0) hd += 360.0;
  h = static_cast<int>(std::lround(hd / 2.0)) % 180;
}

void CloudBuilder::configure(const CloudParams& p, const std::vector<vision::Camera>& cameras,
                             int max_points) {
  const HsvRange& m = p.mask;
  check(m.h_lo >= 0 && m.h_lo < 180 && m.h_hi >= 0 && m.h_hi < 180, "mask.h", "must be in [0, 179]");
  check(m.s_lo >= 0 && m.s_lo <= m.s_hi && m.s_hi <= 255, "mask.s", "must be 0 <= lo <= hi <= 255");
  check(m.v_lo >= 0 && m.v_lo <= m.v_hi && m.v_hi <= 255, "mask.v", "must be 0 <= lo <= hi <= 255");
  check(p.depth_unit_mm > 0.0 && p.depth_unit_mm <= 10.0, "depth_unit_mm", "must be in (0, 10]");
  check(p.min_depth_mm >= 0.0 && p.min_depth_mm < p.max_depth_mm, "min_depth_mm",
        "must be >= 0 and below max_depth_mm");
  check(p.voxel_mm > 0.0 && p.voxel_mm <= 1000.0, "voxel_mm", "must be in (0, 1000]");
  check(max_points >= 1 && max_points <= 50000000, "max_points", "must be in [1, 5e7]");
  check(!cameras.empty(), "cameras", "at least one depth camera");
  check(p.camera_depth_unit_mm.empty() || p.camera_depth_unit_mm.size() == cameras.size(),
        "depth_unit_mm", "one per camera");
  for (const double u : p.camera_depth_unit_mm)
    check(u > 0.0 && u <= 10.0, "depth_unit_mm", "must be in (0, 10]");
  params_ = p;
  cameras_ = cameras;
  units_ = p.camera_depth_unit_mm.empty() ? std::vector<double>(cameras.size(), p.depth_unit_mm)
                                          : p.camera_depth_unit_mm;
  rays_.assign(cameras.size(), {});
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const vision::Camera& cam = cameras[c];
    check(cam.width > 0 && cam.height > 0, "cameras", "a camera without an image size");
    auto& r = rays_[c];
    r.resize(static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height));
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        const cv::Point2d n = cam.undistort({static_cast<double>(u), static_cast<double>(v)});
        r[static_cast<std::size_t>(v) * static_cast<std::size_t>(cam.width) + static_cast<std::size_t>(u)] =
            cv::Vec2f(static_cast<float>(n.x), static_cast<float>(n.y));
      }
    }
  }
  points_.assign(static_cast<std::size_t>(max_points), Eigen::Vector3d::Zero());
  keys_.assign(static_cast<std::size_t>(max_points), 0);
  clear();
}

void CloudBuilder::clear() noexcept {
  count_ = 0;
  counters_ = {};
}

bool CloudBuilder::add_view(int cam, const cv::Mat& depth, const cv::Mat& bgr) noexcept {
  if (cam < 0 || cam >= static_cast<int>(cameras_.size())) return false;
  const vision::Camera& c = cameras_[static_cast<std::size_t>(cam)];
  if (depth.type() != CV_16UC1 || bgr.type() != CV_8UC3 || depth.rows != c.height ||
      depth.cols != c.width || bgr.rows != c.height || bgr.cols != c.width) {
    return false;
  }
  const auto& rays = rays_[static_cast<std::size_t>(cam)];
  const double unit = units_[static_cast<std::size_t>(cam)];
  // world = R^T (p_cam - t)
  Eigen::Matrix3d rt;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rt(i, j) = c.R(j, i);
  const Eigen::Vector3d t(c.t[0], c.t[1], c.t[2]);
  const int cap = static_cast<int>(points_.size());
  for (int v = 0; v < c.height; ++v) {
    const auto* drow = depth.ptr<std::uint16_t>(v);
    const auto* crow = bgr.ptr<std::uint8_t>(v);
    for (int u = 0; u < c.width; ++u) {
      ++counters_.pixels;
      int h, s, val;
      bgr_to_hsv(crow[3 * u], crow[3 * u + 1], crow[3 * u + 2], h, s, val);
      if (!params_.mask.contains(h, s, val)) {
        ++counters_.masked_out;
        continue;
      }
      const double z = drow[u] * unit;
      if (drow[u] == 0 || z < params_.min_depth_mm || z > params_.max_depth_mm) {
        ++counters_.invalid_depth;
        continue;
      }
      if (count_ >= cap) {
        ++counters_.overflow;
        continue;
      }
      const cv::Vec2f& n = rays[static_cast<std::size_t>(v) * static_cast<std::size_t>(c.width) +
                                static_cast<std::size_t>(u)];
      const Eigen::Vector3d pc(n[0] * z, n[1] * z, z);
      points_[static_cast<std::size_t>(count_++)] = rt * (pc - t);
    }
  }
  return true;
}

void CloudBuilder::voxel_downsample() noexcept {
  if (count_ == 0) return;
  // 21 bits per axis around the origin: +-2^20 voxels (+-5.2 km at 5 mm); points outside wrap,
  // which a table-sized scene never reaches.
  constexpr std::int64_t kHalf = std::int64_t{1} << 20;
  constexpr std::uint64_t kMask = (std::uint64_t{1} << 21) - 1;
  const double inv = 1.0 / params_.voxel_mm;
  for (int i = 0; i < count_; ++i) {
    const Eigen::Vector3d& p = points_[static_cast<std::size_t>(i)];
    std::uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
      const auto cell = static_cast<std::int64_t>(std::floor(p[a] * inv)) + kHalf;
      key = (key << 21) | (static_cast<std::uint64_t>(cell) & kMask);
    }
    keys_[static_cast<std::size_t>(i)] = key;
  }
  // In-place heap sort of (keys_, points_) by key: no allocation, deterministic for identical
  // input (the order of points inside a voxel changes their mean only by rounding).
  const auto swap_at = [&](std::size_t a, std::size_t b) {
    std::swap(keys_[a], keys_[b]);
    std::swap(points_[a], points_[b]);
  };
  const std::size_t n = static_cast<std::size_t>(count_);
  const auto sift = [&](std::size_t root, std::size_t end) {
    while (2 * root + 1 < end) {
      std::size_t child = 2 * root + 1;
      if (child + 1 < end && keys_[child] < keys_[child + 1]) ++child;
      if (!(keys_[root] < keys_[child])) return;
      swap_at(root, child);
      root = child;
    }
  };
  for (std::size_t s = n / 2; s-- > 0;) sift(s, n);
  for (std::size_t end = n; end-- > 1;) {
    swap_at(0, end);
    sift(0, end);
  }
  int out = 0;
  std::size_t i = 0;
  while (i < n) {
    std::size_t j = i;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (j < n && keys_[j] == keys_[i]) sum += points_[j++];
    points_[static_cast<std::size_t>(out++)] = sum / static_cast<double>(j - i);
    i = j;
  }
  count_ = out;
}

}  // namespace crease::depth
