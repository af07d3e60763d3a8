// Runs marker detection and triangulation on a worker thread (non-RT: OpenCV allocates) over
// the frame sets a camera source publishes into a frame channel (core/frames), and hands the
// key-points to the vision loop's RT update without locks or allocation.
// The worker holds the channel's reader end. It wakes on every publish (no RT cycle between
// capture and detection: no latency added by the split), processes the newest set in place
// (the images are not copied), and writes the result to a latest channel; the RT side copies
// out the newest result when there is a new one. The RT side never waits.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "core/frames/frame_channel.h"
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

  enum class Take { none, fresh, failed };
  // RT-safe. Copies the newest result into `out` when there is one the caller has not taken
  // (fresh); `failed`: the worker stopped on an exception (see error()).
  Take take_rt(crease::Keypoints& out) noexcept;
  [[nodiscard]] std::uint32_t all_cameras_mask() const noexcept {
    return channel_->all_cameras_mask();
  }
  [[nodiscard]] std::uint64_t sets_processed() const noexcept {
    return processed_.load(std::memory_order_acquire);
  }
  // Detection and triangulation time of the sets processed so far (ns; any thread, RT-safe).
  struct ProcessTimes {
    std::uint64_t count = 0;
    std::int64_t last_ns = 0, max_ns = 0, sum_ns = 0;
  };
  [[nodiscard]] ProcessTimes process_times() const noexcept;
  [[nodiscard]] std::string error() const;  // non-RT, valid after `failed`

 private:
  void run();
  bool claim_reader();  // worker thread; false when asked to stop first

  std::shared_ptr<crease::frames::FrameChannel> channel_;
  KeypointPipeline pipeline_;
  std::unique_ptr<crease::Keypoints> result_;  // worker thread
  std::vector<cv::Mat> images_;                // worker thread: headers over the acquired set
  crease::rt::LatestChannel results_{sizeof(crease::Keypoints)};
  std::uint64_t taken_ = 0;  // RT side: results_ sequence last taken
  std::string error_;
  bool reader_ = false;  // worker thread: holds the channel's reader end
  std::atomic<bool> failed_{false};
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> processed_{0};
  std::atomic<std::int64_t> last_ns_{0}, max_ns_{0}, sum_ns_{0};  // written by the worker only
  std::thread thread_;
};

}  // namespace crease::vision
