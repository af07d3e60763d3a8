// Per-camera marker detection with a fast path (OpenCV aruco underneath):
//  - full-frame search on an image reduced by `decimate`, every `full_search_interval` frames
//    and whenever nothing is tracked;
//  - in between, search only the region predicted from the last detections (constant velocity
//    per tag, the union of their boxes grown by roi_margin sides), at reduced resolution;
//  - tags too small to read at reduced resolution are read from their quads at full resolution;
//  - corners always refined at full resolution by fitting lines to the tag's outer edges.
// Ids above `max_id` (not on the sheet) are dropped. Not RT code: OpenCV allocates.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>

namespace crease::vision {

struct MarkerDetection {
  int id = -1;
  std::array<cv::Point2f, 4> corners;  // full-resolution pixels (centre of pixel (0,0) at 0,0)
};

enum class CornerRefine { kNone, kSubPix, kEdges };

struct DetectorConfig {
  std::string dictionary = "apriltag36h11";
  int max_id = -1;                 // drop ids above (layout max id); -1 keeps all
  int decimate = 2;                // 1 = full resolution search
  int full_search_interval = 8;    // frames between full-frame searches while tracking
  double roi_margin = 1.6;         // predicted region margin, in marker sides (covers neighbours)
  double min_marker_px = 20;       // smallest marker side searched for, full-res pixels
  double error_correction_rate = 0.3;
  // One adaptive-threshold pass (9 px at half resolution, about two cells of a 40 px tag):
  // measured 2026-11 on the vision bench, same recall as aruco's 3..23 sweep at 1/3 the cost.
  int threshold_window_min = 9;    // adaptive threshold windows at search resolution, px
  int threshold_window_max = 9;
  int threshold_window_step = 10;
  CornerRefine refine = CornerRefine::kEdges;
};

class MarkerDetector {
 public:
  explicit MarkerDetector(const DetectorConfig& cfg);

  // Fast path; `gray` is CV_8UC1. Output sorted by id.
  void detect(const cv::Mat& gray, std::vector<MarkerDetection>& out);
  // Forget tracking state (next call does a full search).
  void reset();
  [[nodiscard]] int full_searches() const { return full_searches_; }

 private:
  void search(const cv::Mat& gray, const cv::Rect& roi, int decimate, std::vector<MarkerDetection>& out);
  DetectorConfig cfg_;
  cv::Ptr<cv::aruco::Dictionary> dict_;
  cv::Ptr<cv::aruco::DetectorParameters> params_;
  std::vector<MarkerDetection> last_, prev_;
  int frames_since_full_ = 0;
  int full_searches_ = 0;
  // scratch
  cv::Mat small_;
  std::vector<std::vector<cv::Point2f>> corners_;
  std::vector<int> ids_;
  std::vector<std::vector<cv::Point2f>> rejected_;
};

// Reads the tag inside quad `corners` (full-resolution pixels, clockwise) like aruco does and
// rotates the corners into detector order; false if it is not a tag of `dict`.
bool decode_tag(const cv::Mat& gray, const cv::aruco::Dictionary& dict, double correction_rate,
                std::array<cv::Point2f, 4>& corners, int& id);

// Stock OpenCV: cv::aruco::detectMarkers with default parameters on the full frame.
void detect_stock(const cv::Mat& gray, const cv::Ptr<cv::aruco::Dictionary>& dict,
                  std::vector<MarkerDetection>& out);

// Refines the four corners of one tag by fitting lines to its outer edges (dark inside,
// light outside) at full resolution; returns false (corners untouched) if an edge is not found.
bool refine_corners_edges(const cv::Mat& gray, std::array<cv::Point2f, 4>& corners);

}  // namespace crease::vision
