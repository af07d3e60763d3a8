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

namespace {

// OpenCV's 8-bit hue of a colour whose largest channel is `sector` (0: r, 1: g, 2: b; ties
// resolved in that order), max - min = d > 0 and num the difference of the other two (g - b,
// b - r, r - g): shared by bgr_to_hsv and HsvMask's table, so both agree to the bit.
int hue_of(int sector, int num, int d) noexcept {
  double hd = (sector == 0 ? 0.0 : (sector == 1 ? 120.0 : 240.0)) + 60.0 * num / d;  // degrees
  if (hd < 0.0) hd += 360.0;
  return static_cast<int>(std::lround(hd / 2.0)) % 180;
}

int saturation_of(int mx, int d) noexcept { return mx == 0 ? 0 : (d * 255 + mx / 2) / mx; }

}  // namespace

void bgr_to_hsv(std::uint8_t b, std::uint8_t g, std::uint8_t r, int& h, int& s, int& v) noexcept {
  const int mx = std::max({b, g, r});
  const int mn = std::min({b, g, r});
  const int d = mx - mn;
  v = mx;
  s = saturation_of(mx, d);
  if (d == 0) {
    h = 0;
    return;
  }
  if (mx == r) {
    h = hue_of(0, g - b, d);
  } else if (mx == g) {
    h = hue_of(1, b - r, d);
  } else {
    h = hue_of(2, r - g, d);
  }
}

void HsvMask::configure(const HsvRange& range) {
  sv_ok_.assign(256 * 256, 0);
  for (int mx = 0; mx < 256; ++mx)
    for (int d = 0; d <= mx; ++d) {
      const int s = saturation_of(mx, d);
      sv_ok_[static_cast<std::size_t>(mx * 256 + d)] =
          s >= range.s_lo && s <= range.s_hi && mx >= range.v_lo && mx <= range.v_hi ? 1 : 0;
    }
  const auto h_in = [&](int h) {
    return range.h_lo <= range.h_hi ? (h >= range.h_lo && h <= range.h_hi) : (h >= range.h_lo || h <= range.h_hi);
  };
  h_ok_.assign(3 * 256 * 512, 0);
  for (int sector = 0; sector < 3; ++sector)
    for (int d = 0; d < 256; ++d)
      for (int num = -d; num <= d; ++num)
        h_ok_[static_cast<std::size_t>((sector * 256 + d) * 512 + num + 255)] =
            h_in(d == 0 ? 0 : hue_of(sector, num, d)) ? 1 : 0;
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
  mask_.configure(p.mask);
  const auto cap = static_cast<std::size_t>(max_points);
  points_.assign(cap, Eigen::Vector3d::Zero());
  std::size_t slots = 1024;
  while (slots < 2 * cap) slots *= 2;
  slot_key_.assign(slots, 0);
  slot_voxel_.assign(slots, 0);
  voxel_key_.assign(cap, 0);
  voxel_count_.assign(cap, 0);
  order_.assign(cap, 0);
  clear();
}

void CloudBuilder::clear() noexcept {
  count_ = 0;
  counters_ = {};
}

bool CloudBuilder::add_view(int cam, const cv::Mat& depth, const cv::Mat& bgr) noexcept {
  if (cam < 0 || cam >= static_cast<int>(cameras_.size())) return false;
  const vision::Camera& c = cameras_[static_cast<std::size_t>(cam)];
  return add_view(cam, depth, bgr, c.R, c.t);
}

bool CloudBuilder::add_view(int cam, const cv::Mat& depth, const cv::Mat& bgr, const cv::Matx33d& R,
                            const cv::Vec3d& t_wc) noexcept {
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
    for (int j = 0; j < 3; ++j) rt(i, j) = R(j, i);
  const Eigen::Vector3d t(t_wc[0], t_wc[1], t_wc[2]);
  const int cap = static_cast<int>(points_.size());
  std::int64_t masked_out = 0, invalid_depth = 0, overflow = 0;  // in registers, not in counters_
  for (int v = 0; v < c.height; ++v) {
    const auto* drow = depth.ptr<std::uint16_t>(v);
    const auto* crow = bgr.ptr<std::uint8_t>(v);
    for (int u = 0; u < c.width; ++u) {
      if (!mask_.contains(crow[3 * u], crow[3 * u + 1], crow[3 * u + 2])) {
        ++masked_out;
        continue;
      }
      const double z = drow[u] * unit;
      if (drow[u] == 0 || z < params_.min_depth_mm || z > params_.max_depth_mm) {
        ++invalid_depth;
        continue;
      }
      if (count_ >= cap) {
        ++overflow;
        continue;
      }
      const cv::Vec2f& n = rays[static_cast<std::size_t>(v) * static_cast<std::size_t>(c.width) +
                                static_cast<std::size_t>(u)];
      const Eigen::Vector3d pc(n[0] * z, n[1] * z, z);
      points_[static_cast<std::size_t>(count_++)] = rt * (pc - t);
    }
  }
  counters_.pixels += static_cast<std::int64_t>(c.width) * c.height;
  counters_.masked_out += masked_out;
  counters_.invalid_depth += invalid_depth;
  counters_.overflow += overflow;
  return true;
}

void CloudBuilder::voxel_downsample() noexcept {
  if (count_ == 0) return;
  // 21 bits per axis around the origin: +-2^20 voxels (+-5.2 km at 5 mm); points outside wrap,
  // which a table-sized scene never reaches.
  constexpr std::int64_t kHalf = std::int64_t{1} << 20;
  constexpr std::uint64_t kMask = (std::uint64_t{1} << 21) - 1;
  constexpr std::uint64_t kUsed = std::uint64_t{1} << 63;  // keys take 63 bits
  const double inv = 1.0 / params_.voxel_mm;
  const auto n = static_cast<std::size_t>(count_);
  std::size_t slots = 1024;
  int slot_bits = 10;
  while (slots < 2 * n) slots *= 2, ++slot_bits;  // <= slot_key_.size(): n <= max_points
  const std::size_t slot_mask = slots - 1;
  std::fill(slot_key_.begin(), slot_key_.begin() + static_cast<std::ptrdiff_t>(slots), 0);
  // The sums of voxel v go to points_[v]: v <= i, and points_[v] was read before (or is point i).
  std::size_t voxels = 0, last = 0;
  std::uint64_t last_key = 0;  // neighbouring pixels mostly share a voxel: no probe for them
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = points_[i];
    std::uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
      const auto cell = static_cast<std::int64_t>(std::floor(p[a] * inv)) + kHalf;
      key = (key << 21) | (static_cast<std::uint64_t>(cell) & kMask);
    }
    key |= kUsed;
    std::size_t v;
    if (key == last_key) {
      v = last;
    } else {
      std::size_t s = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - slot_bits));  // Fibonacci hash
      while (slot_key_[s] != 0 && slot_key_[s] != key) s = (s + 1) & slot_mask;
      if (slot_key_[s] == 0) {
        slot_key_[s] = key;
        slot_voxel_[s] = static_cast<std::int32_t>(voxels);
        voxel_key_[voxels] = key;
        voxel_count_[voxels] = 0;
        points_[voxels] = Eigen::Vector3d::Zero();
        ++voxels;
      }
      v = static_cast<std::size_t>(slot_voxel_[s]);
      last_key = key;
      last = v;
    }
    points_[v] += p;
    ++voxel_count_[v];
  }
  for (std::size_t v = 0; v < voxels; ++v) {
    points_[v] /= static_cast<double>(voxel_count_[v]);
    order_[v] = static_cast<std::int32_t>(v);
  }
  // Keys are unique: the order is total, std::sort's (in place, no allocation) is deterministic.
  std::sort(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(voxels),
            [&](std::int32_t a, std::int32_t b) { return voxel_key_[static_cast<std::size_t>(a)] <
                                                         voxel_key_[static_cast<std::size_t>(b)]; });
  // points_[r] = mean of voxel order_[r], in place along the permutation's cycles (voxel_count_
  // marks the places done).
  for (std::size_t start = 0; start < voxels; ++start) {
    if (voxel_count_[start] < 0 || static_cast<std::size_t>(order_[start]) == start) continue;
    const Eigen::Vector3d first = points_[start];
    std::size_t j = start;
    for (;;) {
      voxel_count_[j] = -1;
      const auto k = static_cast<std::size_t>(order_[j]);
      if (k == start) {
        points_[j] = first;
        break;
      }
      points_[j] = points_[k];
      j = k;
    }
  }
  count_ = static_cast<int>(voxels);
}

}  // namespace crease::depth
