// N-view triangulation of one point from calibrated cameras: linear DLT on undistorted
// normalized coordinates, outlier-view rejection by reprojection error (exhaustive over view
// pairs, so one bad view of five cannot drag the estimate), optional Gauss-Newton refinement.
// RT-safe: fixed-size Eigen only, no allocation.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "plugins/camera_rig/camera_model.h"

namespace crease::vision {

constexpr int kMaxViews = 16;

struct ViewObservation {
  int camera = 0;          // index into the camera array (< 32)
  cv::Point2d normalized;  // undistorted normalized image coordinates (x/z, y/z)
};

struct TriangulationConfig {
  double max_reproj_px = 2.0;  // a view farther than this from the estimate is an outlier
  int min_views = 2;
  bool refine = true;          // Gauss-Newton on the inlier views
};

struct TriangulatedPoint {
  cv::Vec3d world_mm;
  double rms_px = 0;       // RMS reprojection error over the inlier views
  std::uint32_t views = 0; // bit per camera index used
  int inliers = 0;
};

// Linear N-view DLT (no rejection); false if degenerate or the point is behind a camera.
bool triangulate_dlt(const Camera* cams, const ViewObservation* obs, int n, cv::Vec3d& X);

// Robust triangulation; false if fewer than min_views views agree.
bool triangulate(const Camera* cams, const ViewObservation* obs, int n, const TriangulationConfig& cfg,
                 TriangulatedPoint& out);

}  // namespace crease::vision
