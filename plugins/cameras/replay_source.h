// Plays a recording (replay_reader.h) as a camera source: frames are decoded ahead on worker
// threads of its own (each decodes whole frames, the next one not yet claimed) into a bounded
// window, and grab() hands them out in order, at their recorded rate, with their time re-based
// to the replay's start.
//
// Time: the replay starts when the first grab() hands out the first frame (CLOCK_MONOTONIC, as
// everything in the daemon; the camera plugin's first request); that frame is stamped with the
// start and frame i with start + (t_i - t_0), its recorded interval from the first frame kept.
// A grab() that comes before its frame is due waits until then (on the calling worker thread,
// never an RT one). A frame is late when it is handed out at or after the next frame was due
// (its consumer came late, or its decoding had not finished): the replay could not keep its
// recorded rate there. A late frame is stamped with the time it is handed out and the replay's
// start moves by what was lost, so the frames after it keep their recorded intervals from it: a
// replay that cannot keep up plays slower, never with stamps that fall ever further into the past
// (a model drops key-points older than its extrapolation horizon). How far behind the recording
// it is, lag = hand-out time - (first start + t_i - t_0), and the late frames are counted.
// Not RT: the counters below are atomics any thread (an RT update too) may read.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "plugins/camera_rig/depth_camera.h"
#include "plugins/cameras/camera_source.h"
#include "plugins/cameras/replay_reader.h"

namespace crease::vision {

class ReplaySource final : public CameraSource {
 public:
  static constexpr std::size_t kDefaultReadAhead = 4;  // frame sets decoded ahead (5 x 1.2 MB each)
  static constexpr int kDefaultDecoders = 2;
  // Reads the directory (throws crease::ConfigError as ReplayReader) and starts decoding ahead,
  // up to `read_ahead` (>= 1) frames not yet handed out, on `decoders` (>= 1) threads named
  // crease-replay-K on the non-RT CPUs.
  explicit ReplaySource(const std::string& dir, std::size_t read_ahead = kDefaultReadAhead,
                        int decoders = kDefaultDecoders);
  ~ReplaySource() override;
  ReplaySource(const ReplaySource&) = delete;
  ReplaySource& operator=(const ReplaySource&) = delete;

  [[nodiscard]] const std::vector<Camera>& cameras() const override { return reader_.cameras(); }
  // A depth recording (camera_source.h's layout) plays into an RGB-D channel: depth, colour.
  [[nodiscard]] std::vector<crease::frames::CameraSpec> channel_images() const override {
    return reader_.depth_units_mm().empty() ? channel_specs(cameras())
                                            : depth_channel_specs(cameras());
  }
  [[nodiscard]] std::vector<double> depth_units_mm() const override {
    return reader_.depth_units_mm();
  }
  // A depth recording's carried cameras (their poses per frame play with their images).
  [[nodiscard]] std::vector<std::optional<CameraMount>> mounts() const override {
    return reader_.any_carried() ? reader_.mounts() : std::vector<std::optional<CameraMount>>{};
  }
  // The next frame, paced and re-based as above; false after the last one or once cancelled.
  // Throws crease::Error when the decoder failed.
  bool grab(Frame& frame) override;
  void cancel() noexcept override;
  [[nodiscard]] std::size_t frames() const { return reader_.frames(); }
  // Frames decoded and not yet handed out (<= read_ahead). Non-RT (takes the queue's lock).
  [[nodiscard]] std::size_t queued();

  // Progress, any thread. start_ns: the replay's start, moved by every late frame (0 before the
  // first grab); last_delivery_ns: when the newest frame was handed out; lags in ns behind the
  // recording's timeline (last: of the newest frame).
  [[nodiscard]] std::uint64_t played() const noexcept { return played_.load(std::memory_order_acquire); }
  [[nodiscard]] std::uint64_t late() const noexcept { return late_.load(std::memory_order_acquire); }
  [[nodiscard]] std::int64_t last_lag_ns() const noexcept { return last_lag_ns_.load(std::memory_order_acquire); }
  [[nodiscard]] std::int64_t max_lag_ns() const noexcept { return max_lag_ns_.load(std::memory_order_acquire); }
  [[nodiscard]] std::int64_t start_ns() const noexcept { return start_ns_.load(std::memory_order_acquire); }
  // When the first frame was handed out (0 before).
  [[nodiscard]] std::int64_t first_start_ns() const noexcept {
    return first_start_ns_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::int64_t last_delivery_ns() const noexcept {
    return last_delivery_ns_.load(std::memory_order_acquire);
  }

 private:
  void decode_loop(int k);
  [[nodiscard]] std::int64_t interval_ns(std::size_t i) const;  // recorded interval around frame i

  ReplayReader reader_;
  std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;  // a frame decoded or handed out, or stop/cancel
  std::vector<Frame> slots_;         // frame i in slots_[i % capacity_] while ready_ says so
  std::vector<char> ready_;
  std::size_t claimed_ = 0;          // the next frame a decoder takes (< next_ + capacity_)
  std::string error_;                // a decoder's failure, if any
  bool stop_ = false;                // the decoders end (destructor)
  bool cancelled_ = false;           // grab() returns false from now on
  std::size_t next_ = 0;             // the next recorded frame grab() hands out
  std::atomic<std::uint64_t> played_{0}, late_{0};
  std::atomic<std::int64_t> last_lag_ns_{0}, max_lag_ns_{0}, start_ns_{0}, first_start_ns_{0}, last_delivery_ns_{0};
  std::vector<std::thread> decoders_;  // last: started once everything above exists
};

}  // namespace crease::vision
