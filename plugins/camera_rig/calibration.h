// Camera calibration with a ChArUco board (OpenCV aruco): intrinsics from several views of the
// board, extrinsics of every camera from one view of a board they all see. The world frame of
// the extrinsics is the board lying printed face up on the table: origin at the board's
// origin corner, x along its squares_x side, z up out of the printed face, millimetres.
#pragma once

#include <string>
#include <vector>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/core.hpp>

#include "plugins/camera_rig/camera_model.h"

namespace crease::vision {

struct CharucoSpec {
  int squares_x = 7;
  int squares_y = 5;
  double square_mm = 30.0;
  double marker_mm = 22.0;
  std::string dictionary = "4x4_50";
};

cv::Ptr<cv::aruco::CharucoBoard> make_charuco(const CharucoSpec& spec);
// Printable board image (white margin of one square), at px_per_mm.
cv::Mat draw_charuco(const CharucoSpec& spec, double px_per_mm, int margin_px = 0);

// Board corners found in one image: ids and pixel positions (empty if the board is not seen).
struct CharucoView {
  std::vector<int> ids;
  std::vector<cv::Point2f> corners;
};
CharucoView detect_charuco(const cv::Mat& gray, const CharucoSpec& spec, const Camera* cam = nullptr);

struct IntrinsicsResult {
  Camera camera;  // pose left at identity
  double rms_px = 0;
  int views_used = 0;
};
// Throws crease::ConfigError when fewer than 4 images show at least 8 board corners, the
// images differ in size or dist_count is not 4, 5 or 8.
IntrinsicsResult calibrate_intrinsics(const std::vector<cv::Mat>& images, const CharucoSpec& spec,
                                      int dist_count = 5);

// Sets cam.R, cam.t (world -> camera) from one image of the board; false if too few corners.
bool board_extrinsics(const cv::Mat& gray, const CharucoSpec& spec, Camera& cam, double* rms_px = nullptr);

// world = board_to_world * board (both right-handed): flips y and z when the board's own y
// axis runs down its printed face (so that z comes out of the face).
cv::Matx33d board_to_world(const CharucoSpec& spec);

}  // namespace crease::vision
