// Runs marker detection and triangulation on a worker thread (non-RT: OpenCV allocates) over
// the frame sets a camera source publishes into a frame channel (core/frames), and hands the
// key-points to the vision loop's RT update without locks or allocation: a FrameSetWorker
// (core/frames/frame_set_worker.h) woken by every publish, the newest set processed in place
// (the images are not copied), the result handed over through a latest channel.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/frames/frame_channel.h"
#include "core/frames/frame_set_worker.h"
#include "core/port_types/keypoints.h"
#include "plugins/vision/keypoint_pipeline.h"
#include "rt/latest.h"

namespace crease::vision {

class VisionWorker {
 public:
  // `cameras` are the calibrations of the channel's cameras, in its order (names and sizes must
  // match: a caller's promise, CREASE_DEMAND). The reader end is claimed now if free, else on the
  // worker thread as soon as the previous reader releases it (a hot swap). camera_threads:
  // KeypointPipeline's (0: cameras through cv::parallel_for_; N >= 1: on this worker and N-1
  // helper threads of ours).
  VisionWorker(std::shared_ptr<crease::frames::FrameChannel> channel, std::vector<Camera> cameras,
               const MarkerLayout& layout, const DetectorConfig& det,
               const TriangulationConfig& tri, int camera_threads = 0);
  ~VisionWorker();
  VisionWorker(const VisionWorker&) = delete;
  VisionWorker& operator=(const VisionWorker&) = delete;

  using Take = crease::frames::FrameSetWorker::Take;
  // RT-safe. Copies the newest result into `out` when there is one the caller has not taken
  // (fresh); `failed`: the worker stopped on an exception (see error()).
  Take take_rt(crease::Keypoints& out) noexcept { return worker_.take_rt(&out); }
  [[nodiscard]] std::uint32_t all_cameras_mask() const noexcept {
    return worker_.channel().all_cameras_mask();
  }
  [[nodiscard]] std::uint64_t sets_processed() const noexcept { return worker_.sets_processed(); }
  // Detection and triangulation time of the sets processed so far (ns; any thread, RT-safe).
  struct ProcessTimes {
    std::uint64_t count = 0;
    std::int64_t last_ns = 0, max_ns = 0, sum_ns = 0;
  };
  [[nodiscard]] ProcessTimes process_times() const noexcept;
  [[nodiscard]] std::string error() const { return worker_.error(); }  // non-RT, valid after `failed`

 private:
  void process(const crease::frames::FrameSet& set);  // worker thread

  KeypointPipeline pipeline_;
  std::unique_ptr<crease::Keypoints> result_;  // worker thread
  std::vector<cv::Mat> images_;                // worker thread: headers over the acquired set
  std::atomic<std::int64_t> last_ns_{0}, max_ns_{0}, sum_ns_{0};  // written by the worker only
  crease::frames::FrameSetWorker worker_;  // last: its thread stops before the members above go
};

}  // namespace crease::vision
