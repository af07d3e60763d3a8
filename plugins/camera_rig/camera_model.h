// Calibrated pinhole camera with OpenCV distortion (k1 k2 p1 p2 [k3 [k4 k5 k6]]) and its
// world->camera pose; loading and saving in OpenCV FileStorage YAML (the calibration format).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace crease::vision {

struct Camera {
  std::string name;
  int width = 0;   // pixels
  int height = 0;  // pixels
  cv::Matx33d K = cv::Matx33d::eye();
  std::array<double, 8> dist{};  // k1 k2 p1 p2 k3 k4 k5 k6 (unused ones are zero)
  int dist_count = 5;            // how many coefficients the file carries (4, 5 or 8)
  cv::Matx33d R = cv::Matx33d::eye();  // world -> camera rotation
  cv::Vec3d t;                         // world -> camera translation, mm

  [[nodiscard]] cv::Vec3d to_camera(const cv::Vec3d& world_mm) const { return R * world_mm + t; }
  [[nodiscard]] cv::Vec3d centre_world() const { return -(R.t() * t); }
  // Normalized (x/z, y/z) -> distorted pixel. RT-safe.
  [[nodiscard]] cv::Point2d distort(const cv::Point2d& normalized) const;
  // World point (mm) -> pixel; false when behind the camera. RT-safe.
  bool project(const cv::Vec3d& world_mm, cv::Point2d& pixel) const;
  // Pixel -> undistorted normalized coordinates (fixed-point iteration). RT-safe.
  [[nodiscard]] cv::Point2d undistort(const cv::Point2d& pixel) const;
  [[nodiscard]] double mean_focal_px() const { return 0.5 * (K(0, 0) + K(1, 1)); }
  [[nodiscard]] cv::Mat dist_mat() const;  // 1xN CV_64F, N = dist_count
};

// A camera `dist_mm` from `target` (world mm) looking at it, image up roughly along world +z.
Camera look_at_camera(const std::string& name, int width, int height, double focal_px,
                      const cv::Vec3d& eye_mm, const cv::Vec3d& target_mm);

// The five-camera rig of seed 000 (Sec. IV) around a table whose origin is the sheet centre:
// one camera overhead, four at the corners 45 degrees up, 1280x960, f = 1400 px, mild
// barrel distortion. Used for config/cameras/ and the synthetic tests.
std::vector<Camera> default_rig();

// Throws crease::ConfigError "<path>: key '<key>': <reason>" on an unreadable file, a missing
// key, a matrix of the wrong size, a non-positive focal length or a rotation that is not one.
Camera load_camera(const std::string& path);
// Throws crease::Error naming the file when it cannot be written.
void save_camera(const Camera& cam, const std::string& path);

// Loads DIR/cam0.yaml, DIR/cam1.yaml, ... (consecutive from 0) or the files listed; throws
// crease::ConfigError if none is found.
std::vector<Camera> load_camera_dir(const std::string& dir);

}  // namespace crease::vision
