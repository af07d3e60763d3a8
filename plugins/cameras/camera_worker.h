// Runs a camera source on a worker thread and publishes its frames into a frame channel
// (core/frames): the camera plugins' engine. Not RT: grabbing, rendering, file and device I/O
// and OpenCV allocate. The RT update only requests frames and learns what was published.
// Protocol, one frame in flight: the RT side requests (idle -> requested, futex wake); the worker
// grabs, records (optional), copies the images into the channel's write set and publishes
// (busy), then marks it done; the RT side takes the announcement and may request the next.
// The RT side never waits.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "core/frames/frame_channel.h"
#include "plugins/cameras/camera_source.h"

namespace crease::vision {

class CameraWorker {
 public:
  // Takes the source; `channel` must have the source's cameras (channel_specs of
  // plugins/camera_rig/images_port.h; CREASE_DEMAND). `record_dir` non-empty writes every
  // grabbed frame there in the replay layout. The writer end of the channel is claimed on the
  // worker thread before the first grab (waiting, off RT, for a previous writer to release it:
  // a hot swap).
  CameraWorker(std::unique_ptr<CameraSource> source,
               std::shared_ptr<crease::frames::FrameChannel> channel,
               const std::string& record_dir);
  ~CameraWorker();
  CameraWorker(const CameraWorker&) = delete;
  CameraWorker& operator=(const CameraWorker&) = delete;

  struct Published {
    std::uint64_t sequence = 0;  // channel sequence
    std::uint64_t frame = 0;     // the source's frame index
    std::int64_t stamp_ns = 0;   // capture time
    std::uint32_t valid_mask = 0;
  };
  enum class Take { none, fresh, ended, failed };
  // RT-safe. If a published frame waits, fills `out` (fresh). Then, if `request` and the worker
  // is idle, asks for the next frame. `ended`: the source has no more frames; `failed`: the
  // worker stopped on an exception (see error()).
  Take take_and_request_rt(Published& out, bool request) noexcept;
  [[nodiscard]] bool idle_rt() const noexcept {
    return state_.load(std::memory_order_acquire) == kIdle;
  }
  [[nodiscard]] std::string error() const;  // non-RT, valid after `failed`
  [[nodiscard]] const crease::frames::FrameChannel& channel() const noexcept { return *channel_; }

 private:
  enum State : int { kIdle, kRequested, kBusy, kDone, kEnded, kFailed, kStop };
  void run();
  bool claim_writer();  // worker thread; false when asked to stop first
  void point_at_write_set();
  std::uint32_t copy_into_channel();

  std::unique_ptr<CameraSource> source_;
  std::shared_ptr<crease::frames::FrameChannel> channel_;
  std::unique_ptr<Recorder> recorder_;
  Frame frame_;
  Published published_;  // owned by whoever the state says
  std::string error_;
  bool writer_ = false;  // worker thread: holds the channel's writer end
  std::atomic<int> state_{kIdle};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace crease::vision
