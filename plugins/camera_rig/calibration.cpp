#include "plugins/camera_rig/calibration.h"

#include <opencv2/calib3d.hpp>

#include "core/assert.h"
#include "plugins/camera_rig/marker_layout.h"

namespace crease::vision {

cv::Ptr<cv::aruco::CharucoBoard> make_charuco(const CharucoSpec& s) {
  crease::require_input(s.squares_x >= 3 && s.squares_y >= 3, "ChArUco board needs at least 3x3 squares");
  crease::require_input(s.marker_mm > 0 && s.marker_mm < s.square_mm, "ChArUco marker must be smaller than its square");
  return cv::aruco::CharucoBoard::create(s.squares_x, s.squares_y, static_cast<float>(s.square_mm),
                                         static_cast<float>(s.marker_mm), dictionary_by_name(s.dictionary));
}

cv::Mat draw_charuco(const CharucoSpec& s, double ppm, int margin) {
  cv::Mat img;
  const cv::Size size(static_cast<int>(std::lround(s.squares_x * s.square_mm * ppm)) + 2 * margin,
                      static_cast<int>(std::lround(s.squares_y * s.square_mm * ppm)) + 2 * margin);
  make_charuco(s)->draw(size, img, margin, 1);
  return img;
}

CharucoView detect_charuco(const cv::Mat& gray, const CharucoSpec& s, const Camera* cam) {
  const auto board = make_charuco(s);
  std::vector<std::vector<cv::Point2f>> mc;
  std::vector<int> mid;
  cv::aruco::detectMarkers(gray, board->dictionary, mc, mid);
  CharucoView v;
  if (mid.empty()) return v;
  if (cam != nullptr)
    cv::aruco::interpolateCornersCharuco(mc, mid, gray, board, v.corners, v.ids, cv::Mat(cam->K), cam->dist_mat());
  else
    cv::aruco::interpolateCornersCharuco(mc, mid, gray, board, v.corners, v.ids);
  return v;
}

IntrinsicsResult calibrate_intrinsics(const std::vector<cv::Mat>& images, const CharucoSpec& s, int dist_count) {
  crease::require_input(dist_count == 4 || dist_count == 5 || dist_count == 8,
                        "distortion model must have 4, 5 or 8 coefficients");
  const auto board = make_charuco(s);
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<std::vector<int>> ids;
  cv::Size size;
  for (const cv::Mat& img : images) {
    if (img.empty()) continue;
    if (size.area() == 0) size = img.size();
    crease::require_input(img.size() == size, "calibration images differ in size");
    CharucoView v = detect_charuco(img, s);
    if (v.ids.size() < 8) continue;
    corners.push_back(std::move(v.corners));
    ids.push_back(std::move(v.ids));
  }
  crease::require_input(corners.size() >= 4, "only " + std::to_string(corners.size()) +
                                                 " images show the ChArUco board (need 4 with >= 8 corners)");
  cv::Mat K, dist;
  int flags = 0;
  if (dist_count == 8) flags |= cv::CALIB_RATIONAL_MODEL;
  if (dist_count == 4) flags |= cv::CALIB_FIX_K3;
  IntrinsicsResult r;
  r.rms_px = cv::aruco::calibrateCameraCharuco(corners, ids, board, size, K, dist, cv::noArray(), cv::noArray(), flags);
  r.views_used = static_cast<int>(corners.size());
  r.camera.width = size.width;
  r.camera.height = size.height;
  r.camera.K = cv::Matx33d(K.ptr<double>());
  r.camera.dist_count = dist_count;
  dist.convertTo(dist, CV_64F);
  for (int i = 0; i < dist_count && i < static_cast<int>(dist.total()); ++i)
    r.camera.dist[static_cast<std::size_t>(i)] = dist.at<double>(i);
  return r;
}

cv::Matx33d board_to_world(const CharucoSpec& s) {
  // Board marker 0's first corner is its top-left as printed, its fourth the bottom-left:
  // if the board's y grows from the first to the fourth, y runs down the printed face.
  const auto board = make_charuco(s);
  const auto& m0 = board->objPoints[0];
  const bool y_down = m0[3].y > m0[0].y;
  return y_down ? cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) : cv::Matx33d::eye();
}

bool board_extrinsics(const cv::Mat& gray, const CharucoSpec& s, Camera& cam, double* rms_px) {
  const auto board = make_charuco(s);
  const CharucoView v = detect_charuco(gray, s, &cam);
  if (v.ids.size() < 6) return false;
  cv::Vec3d rvec, tvec;
  if (!cv::aruco::estimatePoseCharucoBoard(v.corners, v.ids, board, cv::Mat(cam.K), cam.dist_mat(), rvec, tvec))
    return false;
  cv::Matx33d Rcb;
  cv::Rodrigues(rvec, Rcb);
  // x_cam = Rcb x_board + t, x_board = W^T x_world (W orthonormal).
  cam.R = Rcb * board_to_world(s).t();
  cam.t = tvec;
  if (rms_px != nullptr) {
    double se = 0;
    for (std::size_t i = 0; i < v.ids.size(); ++i) {
      const cv::Point3f& o = board->chessboardCorners[static_cast<std::size_t>(v.ids[i])];
      cv::Point2d px;
      cam.project(board_to_world(s) * cv::Vec3d(o.x, o.y, o.z), px);
      se += std::pow(cv::norm(px - cv::Point2d(v.corners[i])), 2);
    }
    *rms_px = std::sqrt(se / static_cast<double>(v.ids.size()));
  }
  return true;
}

}  // namespace crease::vision
