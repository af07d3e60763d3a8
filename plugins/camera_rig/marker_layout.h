// Marker layout of the printed sheet: which AprilTag id sits where, on which face.
// All positions are sheet coordinates (u, v) in mm of the FRONT face (DESIGN.md): origin at
// the top-left corner of the printed front page, u right along the short edge, v down.
// Back-face markers are given at the same physical point in front coordinates; the back page
// is printed mirrored in u (duplex, flip on the long edge), so a back marker's corners, listed
// in reading order as seen from the back, run counter-clockwise in (u, v).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>

namespace crease::vision {

enum class Face : int { kFront = 0, kBack = 1 };

struct MarkerPlacement {
  int id = 0;
  Face face = Face::kFront;
  cv::Point2d centre_mm;
  std::array<cv::Point2d, 4> corners_mm;  // detector order: TL, TR, BR, BL as the tag is read
};

struct LayoutSpec {
  std::string paper = "a4";
  std::string dictionary = "apriltag36h11";
  double marker_mm = 28.0;  // outer side of the tag including its black border
  int cols = 5;
  int rows = 7;
  bool double_sided = false;
  int first_id = 0;  // front ids first_id.., back ids follow
};

struct MarkerLayout {
  std::string dictionary;
  std::string paper;
  double sheet_w_mm = 0;
  double sheet_h_mm = 0;
  double marker_mm = 0;
  std::vector<MarkerPlacement> markers;

  // Index into markers for a dictionary id, or -1.
  [[nodiscard]] int index_of(int id) const;
  [[nodiscard]] int max_id() const;
};

// Paper size in mm for a name ("a4", "letter", "a3"); throws crease::ConfigError.
cv::Size2d paper_size_mm(const std::string& paper);
// OpenCV predefined dictionary for a name ("apriltag36h11", "apriltag25h9", "4x4_50", ...);
// throws crease::ConfigError naming the dictionary.
cv::Ptr<cv::aruco::Dictionary> dictionary_by_name(const std::string& name);

// A regular grid of markers per face, centred on the page; throws crease::ConfigError on a grid
// that does not fit the paper or needs more ids than the dictionary has.
MarkerLayout make_layout(const LayoutSpec& spec);

// Throws crease::Error naming the file when it cannot be written.
void save_layout(const MarkerLayout& layout, const std::string& path);
// Throws crease::ConfigError "FILE:LINE:COLUMN: KEY: reason" on a missing or malformed entry
// ("FILE: cannot read layout file", "FILE: line N: ..." for an unreadable or non-YAML file).
MarkerLayout load_layout(const std::string& path);

}  // namespace crease::vision
