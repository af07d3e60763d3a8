// Images of N calibrated cameras -> marker detections (cameras in parallel) -> five key-points
// per marker (centre, four corners) -> N-view triangulation -> crease::Keypoints.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "core/port_types/keypoints.h"
#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/marker_layout.h"
#include "plugins/vision/marker_detector.h"
#include "plugins/vision/task_team.h"
#include "plugins/vision/triangulation.h"

namespace crease::vision {

// Centre of a tag in undistorted normalized coordinates: intersection of the diagonals of
// its undistorted corners (exact for a planar tag under perspective).
cv::Point2d tag_centre_normalized(const Camera& cam, const std::array<cv::Point2f, 4>& corners);

// Triangulates every key-point seen by >= 2 cameras. detections[k] belongs to cams[k].
// Fills out.points/count (capacity-limited); leaves timestamp/frame/cameras_ok alone.
void build_keypoints(const std::vector<Camera>& cams, const MarkerLayout& layout,
                     const std::vector<std::vector<MarkerDetection>>& detections,
                     const TriangulationConfig& tri, crease::Keypoints& out);

class KeypointPipeline {
 public:
  // camera_threads: 0 detects the cameras in parallel through cv::parallel_for_ (OpenCV's
  // pool); N >= 1 on N threads of our own, the caller of process() and N-1 helpers (TaskTeam;
  // 1: one camera after the other on the caller). Negative: a caller's bug (CREASE_DEMAND).
  KeypointPipeline(std::vector<Camera> cams, MarkerLayout layout, DetectorConfig det,
                   TriangulationConfig tri, int camera_threads = 0);

  // images[k] from camera k (CV_8UC1, or empty when camera k delivered nothing this frame).
  void process(const std::vector<cv::Mat>& images, std::int64_t timestamp_ns, crease::Keypoints& out);
  [[nodiscard]] const std::vector<std::vector<MarkerDetection>>& detections() const { return dets_; }
  [[nodiscard]] const std::vector<Camera>& cameras() const { return cams_; }
  [[nodiscard]] const MarkerLayout& layout() const { return layout_; }
  void reset();

 private:
  std::vector<Camera> cams_;
  MarkerLayout layout_;
  TriangulationConfig tri_;
  std::vector<MarkerDetector> detectors_;
  std::vector<std::vector<MarkerDetection>> dets_;
  std::unique_ptr<TaskTeam> team_;  // camera_threads >= 1
  std::uint64_t frame_ = 0;
};

}  // namespace crease::vision
