// Runs camera capture, detection and triangulation on a worker thread (non-RT: OpenCV
// allocates), handing key-points to the vision loop's RT update without locks or allocation.
// Protocol, one frame in flight: the RT side requests a frame (idle -> requested, futex wake),
// the worker grabs + processes into its result buffer (busy), then marks it done; the RT side
// copies the result out and returns the slot to idle. The RT side never waits.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "camera_source.h"
#include "core/port_types/keypoints.h"
#include "keypoint_pipeline.h"

namespace crease::vision {

class VisionWorker {
 public:
  // Takes ownership of the source; `record_dir` non-empty writes every frame there.
  VisionWorker(std::unique_ptr<CameraSource> source, const MarkerLayout& layout, const DetectorConfig& det,
               const TriangulationConfig& tri, const std::string& record_dir);
  ~VisionWorker();
  VisionWorker(const VisionWorker&) = delete;
  VisionWorker& operator=(const VisionWorker&) = delete;

  enum class Take { none, fresh, ended, failed };
  // RT-safe. If a processed frame is waiting, copies it into `out` (fresh). Then, if the worker
  // is idle, requests the next frame. `ended`: the source has no more frames; `failed`: the
  // worker stopped on an exception (see error()).
  Take take_and_request_rt(crease::Keypoints& out) noexcept;
  [[nodiscard]] std::uint32_t all_cameras_mask() const noexcept { return all_mask_; }
  [[nodiscard]] std::string error() const;  // non-RT, valid after `failed`

 private:
  enum State : int { kIdle, kRequested, kBusy, kDone, kEnded, kFailed, kStop };
  void run();

  std::unique_ptr<CameraSource> source_;
  std::unique_ptr<Recorder> recorder_;
  KeypointPipeline pipeline_;
  std::unique_ptr<crease::Keypoints> result_;  // owned by whoever the state says
  Frame frame_;
  std::uint32_t all_mask_ = 0;
  std::string error_;
  std::atomic<int> state_{kIdle};
  std::thread thread_;
};

}  // namespace crease::vision
