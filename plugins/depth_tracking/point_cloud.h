// World-frame point clouds from registered depth + colour images (seed 001 Sec. III-B): a
// pixel becomes a point when its colour lies in the HSV range of the sheet AND its depth is
// valid; it is back-projected through the calibrated camera (plugins/camera_rig, distortion
// included, depth = z along the optical axis), then the fused cloud is voxel-downsampled.
//
// configure() allocates everything (the per-pixel ray tables of each camera, the point buffer
// of max_points, the mask's lookup tables, the voxel hash table); clear()/add_view()/
// voxel_downsample() allocate nothing and throw nothing.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "plugins/camera_rig/camera_model.h"

namespace crease::depth {

// OpenCV's 8-bit HSV: h in [0, 180) (degrees / 2), s and v in [0, 255]. h_lo > h_hi wraps
// through 0 (reds).
struct HsvRange {
  int h_lo = 0, h_hi = 179;
  int s_lo = 0, s_hi = 255;
  int v_lo = 0, v_hi = 255;
  [[nodiscard]] bool contains(int h, int s, int v) const noexcept {
    const bool h_in = h_lo <= h_hi ? (h >= h_lo && h <= h_hi) : (h >= h_lo || h <= h_hi);
    return h_in && s >= s_lo && s <= s_hi && v >= v_lo && v <= v_hi;
  }
};

// BGR (8 bit) -> OpenCV 8-bit HSV, as cv::cvtColor(COLOR_BGR2HSV). RT-safe.
void bgr_to_hsv(std::uint8_t b, std::uint8_t g, std::uint8_t r, int& h, int& s, int& v) noexcept;

// HsvRange::contains(bgr_to_hsv(b, g, r)) by two table look-ups (the same arithmetic, tabulated
// at configure): v and s depend on (max, max - min) only, h on which channel is the largest,
// max - min and the difference of the other two. Non-RT to build (~460 kB), RT-safe to use.
class HsvMask {
 public:
  void configure(const HsvRange& range);
  [[nodiscard]] bool contains(std::uint8_t b, std::uint8_t g, std::uint8_t r) const noexcept {
    const int mx = std::max(b, std::max(g, r)), mn = std::min(b, std::min(g, r)), d = mx - mn;
    if (!sv_ok_[static_cast<std::size_t>(mx * 256 + d)]) return false;
    // The channel bgr_to_hsv takes as the maximum (r first, then g) and its hue numerator.
    const int sector = mx == r ? 0 : (mx == g ? 1 : 2);
    const int num = sector == 0 ? g - b : (sector == 1 ? b - r : r - g);
    return h_ok_[static_cast<std::size_t>((sector * 256 + d) * 512 + num + 255)] != 0;
  }

 private:
  std::vector<std::uint8_t> sv_ok_;  // [max][max - min]: v and s in range
  std::vector<std::uint8_t> h_ok_;   // [sector][max - min][numerator + 255]: h in range
};

struct CloudParams {
  HsvRange mask;
  double depth_unit_mm = 1.0;   // one depth count in mm (D435 default 1 mm, D405 0.1 mm)
  // Per camera (the calibrations' depth_unit_mm), overriding depth_unit_mm; empty: that for all.
  std::vector<double> camera_depth_unit_mm;
  double min_depth_mm = 100.0;  // valid depth range along the optical axis, mm
  double max_depth_mm = 3000.0;
  double voxel_mm = 5.0;        // leaf size of the voxel grid, mm (> 0)
};

struct CloudCounters {
  std::int64_t pixels = 0;         // pixels looked at
  std::int64_t masked_out = 0;     // colour outside the range
  std::int64_t invalid_depth = 0;  // colour in range, depth 0 or out of range
  std::int64_t overflow = 0;       // points lost because the buffer was full
};

class CloudBuilder {
 public:
  // Non-RT. Throws crease::ConfigError naming the field on a bad range; one ray table per
  // camera (its pixel grid undistorted once).
  void configure(const CloudParams& params, const std::vector<vision::Camera>& cameras,
                 int max_points);

  void clear() noexcept;  // empties the cloud and the counters
  // Adds the masked, valid pixels of camera `cam`'s view: depth CV_16UC1 in depth units, colour
  // CV_8UC3 BGR registered to it, both the camera's size, put in the world with the camera's
  // calibrated pose. False (nothing added) on a wrong index, size or type. RT-safe.
  bool add_view(int cam, const cv::Mat& depth, const cv::Mat& bgr) noexcept;
  // The same from where the camera was at this view's capture: (R, t) its world -> camera pose
  // then (a camera the robot carries; the intrinsics, and so the ray table, do not move). RT-safe.
  bool add_view(int cam, const cv::Mat& depth, const cv::Mat& bgr, const cv::Matx33d& R,
                const cv::Vec3d& t) noexcept;
  // Replaces the cloud by one point per occupied voxel (the mean of its points, summed in the
  // order they were added); the order is that of the voxel keys (deterministic). RT-safe.
  void voxel_downsample() noexcept;

  [[nodiscard]] std::span<const Eigen::Vector3d> points() const noexcept {
    return {points_.data(), static_cast<std::size_t>(count_)};
  }
  [[nodiscard]] const CloudCounters& counters() const noexcept { return counters_; }

 private:
  CloudParams params_;
  std::vector<vision::Camera> cameras_;
  std::vector<double> units_;                 // per camera, mm per count
  std::vector<std::vector<cv::Vec2f>> rays_;  // per camera, per pixel: undistorted (x/z, y/z)
  HsvMask mask_;
  std::vector<Eigen::Vector3d> points_;       // capacity max_points
  // Voxel grid: open addressing (linear probing) over the first power of two >= 2 x the points of
  // this frame (so never full); a slot holds its voxel's key | kUsed and the voxel's number.
  std::vector<std::uint64_t> slot_key_;       // power of two >= 2 max_points
  std::vector<std::int32_t> slot_voxel_;
  std::vector<std::uint64_t> voxel_key_;      // per voxel, capacity max_points
  std::vector<std::int32_t> voxel_count_;     // per voxel: its points
  std::vector<std::int32_t> order_;           // the voxels by key
  int count_ = 0;
  CloudCounters counters_;
};

}  // namespace crease::depth
