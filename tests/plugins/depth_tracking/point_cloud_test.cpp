// CloudBuilder (plugins/depth_tracking/point_cloud.h): a synthetic registered depth + colour view
// of a flat table with a blue sheet on it and a red region (a hand's colour) on the sheet.
#include "plugins/depth_tracking/point_cloud.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "rt/alloc_guard.h"

using crease::depth::CloudBuilder;
using crease::depth::CloudParams;
using crease::depth::HsvMask;
using crease::depth::HsvRange;

namespace {

constexpr double kNoiseMm = 1.0;  // depth noise sigma of the synthetic view
const cv::Vec3b kSheet(220, 160, 60);  // BGR, a light blue paper: h ~ 102, s ~ 185
const cv::Vec3b kHand(60, 70, 210);    // BGR, red-ish
const cv::Vec3b kTable(128, 128, 128);  // grey, s = 0

bool in_sheet(double x, double y) { return std::abs(x) < 100.0 && std::abs(y) < 140.0; }
bool in_hand(double x, double y) { return x > 20.0 && x < 80.0 && y > -40.0 && y < 40.0; }

struct View {
  crease::vision::Camera cam;
  cv::Mat depth, bgr;
  int sheet_pixels = 0;  // pixels that see the sheet outside the hand
};

// The table is the plane z = 0 (world mm); the camera 800 mm above, slightly oblique.
View render(unsigned seed) {
  View v;
  v.cam = crease::vision::look_at_camera("depth0", 320, 240, 300.0, {60.0, -80.0, 800.0}, {0.0, 0.0, 0.0});
  v.cam.dist = {-0.05, 0.01, 0, 0, 0, 0, 0, 0};
  v.depth = cv::Mat(v.cam.height, v.cam.width, CV_16UC1);
  v.bgr = cv::Mat(v.cam.height, v.cam.width, CV_8UC3);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, kNoiseMm);
  const cv::Vec3d c = v.cam.centre_world();
  for (int r = 0; r < v.cam.height; ++r)
    for (int u = 0; u < v.cam.width; ++u) {
      const cv::Point2d n = v.cam.undistort({double(u), double(r)});
      const cv::Vec3d d = v.cam.R.t() * cv::Vec3d(n.x, n.y, 1.0);  // world direction, z_cam = 1
      const double s = -c[2] / d[2];                                 // hits z = 0 at c + s d
      const cv::Vec3d p = c + s * d;
      const double z_cam = s;  // d has unit z in the camera frame
      v.depth.at<std::uint16_t>(r, u) = static_cast<std::uint16_t>(std::lround(z_cam + noise(rng)));
      cv::Vec3b col = kTable;
      if (in_sheet(p[0], p[1])) col = in_hand(p[0], p[1]) ? kHand : kSheet;
      if (col == kSheet) ++v.sheet_pixels;
      v.bgr.at<cv::Vec3b>(r, u) = col;
    }
  return v;
}

CloudParams sheet_mask() {
  CloudParams p;
  p.mask = {90, 115, 100, 255, 80, 255};
  p.voxel_mm = 5.0;
  return p;
}

}  // namespace

TEST_CASE("bgr_to_hsv agrees with OpenCV's COLOR_BGR2HSV") {
  cv::Mat bgr(1, 512, CV_8UC3), hsv;
  std::mt19937 rng(7);
  for (int i = 0; i < 512; ++i)
    bgr.at<cv::Vec3b>(0, i) = cv::Vec3b(std::uint8_t(rng()), std::uint8_t(rng()), std::uint8_t(rng()));
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  for (int i = 0; i < 512; ++i) {
    const cv::Vec3b b = bgr.at<cv::Vec3b>(0, i), o = hsv.at<cv::Vec3b>(0, i);
    int h, s, v;
    crease::depth::bgr_to_hsv(b[0], b[1], b[2], h, s, v);
    CHECK(std::abs(h - o[0]) % 179 <= 1);  // rounding; 0 and 179 are neighbours
    CHECK(std::abs(s - o[1]) <= 1);
    CHECK(v == o[2]);
  }
}

TEST_CASE("the mask's tables decide as bgr_to_hsv and HsvRange::contains, for every colour") {
  // The cloud's range, one whose hue wraps through 0 (reds) with tight s and v, a grey band.
  const HsvRange ranges[] = {{90, 115, 100, 255, 80, 255}, {170, 8, 60, 200, 30, 220}, {0, 179, 0, 12, 100, 140}};
  for (const HsvRange& range : ranges) {
    HsvMask mask;
    mask.configure(range);
    long long mismatches = 0, inside = 0;
    for (int b = 0; b < 256; ++b)
      for (int g = 0; g < 256; ++g)
        for (int r = 0; r < 256; ++r) {
          int h, s, v;
          crease::depth::bgr_to_hsv(std::uint8_t(b), std::uint8_t(g), std::uint8_t(r), h, s, v);
          const bool want = range.contains(h, s, v);
          inside += want;
          mismatches += want != mask.contains(std::uint8_t(b), std::uint8_t(g), std::uint8_t(r));
        }
    MESSAGE("h " << range.h_lo << ".." << range.h_hi << ": " << inside << " colours inside");
    CHECK(inside > 0);
    CHECK(mismatches == 0);
  }
}

TEST_CASE("a flat sheet back-projects to its plane; the mask keeps the sheet, drops the hand") {
  const View v = render(1);
  CloudBuilder b;
  b.configure(sheet_mask(), {v.cam}, 200000);
  REQUIRE(b.add_view(0, v.depth, v.bgr));
  const auto pts = b.points();
  REQUIRE(v.sheet_pixels > 5000);
  CHECK(static_cast<double>(pts.size()) >= 0.99 * v.sheet_pixels);
  CHECK(static_cast<int>(pts.size()) <= v.sheet_pixels);
  double sum_sq = 0.0, worst = 0.0;
  int in_hand_points = 0;
  for (const auto& p : pts) {
    sum_sq += p.z() * p.z();
    worst = std::max(worst, std::abs(p.z()));
    if (in_hand(p.x(), p.y()) && p.x() > 22.0 && p.x() < 78.0 && p.y() > -38.0 && p.y() < 38.0) ++in_hand_points;
  }
  const double rms = std::sqrt(sum_sq / static_cast<double>(pts.size()));
  MESSAGE(pts.size() << " points of " << v.sheet_pixels << " sheet pixels, plane rms " << rms << " mm, worst " << worst);
  // Depth noise 1 mm plus 1 mm quantisation (sigma 0.29), through an oblique ray: well within 1.5 sigma_z.
  CHECK(rms < 1.5 * kNoiseMm);
  CHECK(worst < 6.0 * kNoiseMm);
  CHECK(in_hand_points == 0);
  CHECK(b.counters().masked_out > 0);

  // The variant without the colour mask keeps the hand's pixels (and the table's).
  CloudParams all = sheet_mask();
  all.mask = {};
  CloudBuilder b_all;
  b_all.configure(all, {v.cam}, 200000);
  REQUIRE(b_all.add_view(0, v.depth, v.bgr));
  int hand_all = 0;
  for (const auto& p : b_all.points())
    if (in_hand(p.x(), p.y()) && p.x() > 22.0 && p.x() < 78.0 && p.y() > -38.0 && p.y() < 38.0) ++hand_all;
  CHECK(hand_all > 100);
}

TEST_CASE("invalid depth is dropped and counted; voxel downsampling keeps the plane") {
  View v = render(2);
  CloudParams p10 = sheet_mask();
  p10.voxel_mm = 10.0;  // ~3.7 mm pixels along the oblique view: ~7 points per voxel
  for (int r = 100; r < 120; ++r)
    for (int u = 0; u < v.cam.width; ++u) v.depth.at<std::uint16_t>(r, u) = 0;  // a band of no depth
  CloudBuilder b;
  b.configure(p10, {v.cam}, 200000);
  REQUIRE(b.add_view(0, v.depth, v.bgr));
  CHECK(b.counters().invalid_depth > 0);
  const std::size_t raw = b.points().size();
  double raw_sq = 0.0;
  for (const auto& p : b.points()) raw_sq += p.z() * p.z();
  const double raw_rms = std::sqrt(raw_sq / static_cast<double>(raw));
  REQUIRE(crease::rt::alloc_hooks_installed());
  const auto allocs = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark mark;
    b.clear();
    REQUIRE(b.add_view(0, v.depth, v.bgr));
    b.voxel_downsample();
  }
  CHECK(crease::rt::rt_allocation_count() == allocs);
  const auto pts = b.points();
  CHECK(pts.size() < raw / 3);
  CHECK(pts.size() > 500);
  double worst = 0.0, sq = 0.0;
  for (const auto& p : pts) {
    worst = std::max(worst, std::abs(p.z()));
    sq += p.z() * p.z();
  }
  const double rms = std::sqrt(sq / static_cast<double>(pts.size()));
  MESSAGE(raw << " points -> " << pts.size() << " voxels; plane rms " << raw_rms << " -> " << rms << " mm");
  CHECK(worst < 6.0 * kNoiseMm);
  CHECK(rms < 0.9 * raw_rms);  // the voxel means average the noise down (not the quantisation)
  // Deterministic: the same view gives the same cloud.
  std::vector<Eigen::Vector3d> first(pts.begin(), pts.end());
  b.clear();
  REQUIRE(b.add_view(0, v.depth, v.bgr));
  b.voxel_downsample();
  REQUIRE(b.points().size() == first.size());
  for (std::size_t i = 0; i < first.size(); ++i) CHECK(b.points()[i] == first[i]);
  // A full buffer counts what it lost.
  CloudBuilder small;
  small.configure(sheet_mask(), {v.cam}, 100);
  REQUIRE(small.add_view(0, v.depth, v.bgr));
  CHECK(small.points().size() == 100);
  CHECK(small.counters().overflow > 0);
}

TEST_CASE("voxel downsampling: one mean per occupied voxel, in the order of the voxels' cells") {
  const View v = render(4);
  for (const double voxel : {3.0, 10.0, 40.0}) {
    CloudParams p = sheet_mask();
    p.voxel_mm = voxel;
    CloudBuilder b;
    b.configure(p, {v.cam}, 200000);
    REQUIRE(b.add_view(0, v.depth, v.bgr));
    REQUIRE(b.add_view(0, v.depth, v.bgr));  // every voxel's points twice, and not side by side
    // The reference: the raw points grouped by cell (x, then y, then z: the key's order).
    const double inv = 1.0 / voxel;  // as the builder computes the cells
    std::map<std::array<long long, 3>, std::pair<Eigen::Vector3d, int>> cells;
    for (const auto& q : b.points()) {
      const std::array<long long, 3> cell = {static_cast<long long>(std::floor(q.x() * inv)),
                                             static_cast<long long>(std::floor(q.y() * inv)),
                                             static_cast<long long>(std::floor(q.z() * inv))};
      auto& c = cells.try_emplace(cell, Eigen::Vector3d::Zero(), 0).first->second;
      c.first += q;
      ++c.second;
    }
    b.voxel_downsample();
    REQUIRE(b.points().size() == cells.size());
    double worst = 0.0;
    std::size_t i = 0;
    for (const auto& [cell, sum] : cells) worst = std::max(worst, (b.points()[i++] - sum.first / sum.second).norm());
    MESSAGE(voxel << " mm: " << cells.size() << " voxels, largest difference to the reference " << worst << " mm");
    CHECK(worst < 1e-9);  // the same means, summed in another order
  }
}

TEST_CASE("bad cloud parameters are ConfigErrors naming the key; wrong images are refused") {
  const View v = render(3);
  CloudParams p = sheet_mask();
  p.voxel_mm = 0.0;
  CloudBuilder b;
  try {
    b.configure(p, {v.cam}, 10);
    FAIL("no error");
  } catch (const crease::ConfigError& e) {
    CHECK(std::string(e.what()).find("voxel_mm") != std::string::npos);
  }
  b.configure(sheet_mask(), {v.cam}, 10);
  CHECK_FALSE(b.add_view(1, v.depth, v.bgr));
  cv::Mat d8(v.cam.height, v.cam.width, CV_8UC1);
  CHECK_FALSE(b.add_view(0, d8, v.bgr));
}
