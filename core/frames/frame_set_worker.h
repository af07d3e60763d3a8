// A worker thread over a frame channel's reader end (non-RT), and the lock-free hand-over of its
// newest result to an RT update: what the vision and the depth workers share.
// The worker is woken by every publish (no RT cycle between capture and processing), hands the
// newest set to `process` in place (no copy of the images), finishes the set, and publishes what
// `process` wrote into a latest channel; the RT side copies out the newest result when there is
// one it has not taken, and never waits. An exception from `process` stops the worker: the
// reader end is released (a source in lockstep must not wait for it) and take_rt says `failed`.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "core/frames/frame_channel.h"
#include "rt/latest.h"

namespace crease::frames {

class FrameSetWorker {
 public:
  // Processes one set on the worker thread; writes its result into `result` (result_bytes, the
  // buffer given to start()); may throw.
  using Process = std::function<void(const FrameSet& set)>;

  // `result_bytes`: the size of the result type the latest channel carries.
  FrameSetWorker(std::shared_ptr<FrameChannel> channel, std::size_t result_bytes);
  ~FrameSetWorker();  // stop()
  FrameSetWorker(const FrameSetWorker&) = delete;
  FrameSetWorker& operator=(const FrameSetWorker&) = delete;

  // Claims the reader end now if it is free, else on the worker thread as soon as the previous
  // reader releases it (a hot swap), and starts the thread. `result` (result_bytes, owned by the
  // caller, alive until stop()) is what `process` fills and what is published after each set.
  // Call once, after everything `process` touches is built.
  void start(Process process, const void* result);
  // Stops and joins the thread, releases the reader end; idempotent. Call it before destroying
  // what `process` touches.
  void stop();

  enum class Take { none, fresh, failed };
  // RT-safe. Copies the newest result into `out` (result_bytes) when there is one the caller has
  // not taken (fresh); `failed`: the worker stopped on an exception (see error()).
  Take take_rt(void* out) noexcept;

  [[nodiscard]] const FrameChannel& channel() const noexcept { return *channel_; }
  [[nodiscard]] std::uint64_t sets_processed() const noexcept {
    return processed_.load(std::memory_order_acquire);
  }
  [[nodiscard]] std::string error() const;  // non-RT, valid after `failed`

 private:
  void run();
  bool claim_reader();  // worker thread; false when asked to stop first

  std::shared_ptr<FrameChannel> channel_;
  crease::rt::LatestChannel results_;
  Process process_;
  const void* result_ = nullptr;
  std::uint64_t taken_ = 0;  // RT side: results_ sequence last taken
  std::string error_;
  bool reader_ = false;  // holds the channel's reader end (worker thread once started)
  std::atomic<bool> failed_{false};
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> processed_{0};
  std::thread thread_;
};

}  // namespace crease::frames
