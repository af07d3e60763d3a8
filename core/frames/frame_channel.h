// Frame channel: the newest set of camera images of one camera source, handed from the
// source's worker thread to one consumer (the vision worker) without copying the pixels through
// a latest port. Camera images are megabytes; a latest port carries only the announcement
// (core/port_types/camera_frames.h). The host's PortRegistry owns the channels, as ports of
// kind `frames` (bound through PortBinder::frames_output / frames_input, listed with the other
// ports); this class is the channel itself.
//
// A triple buffer of frame sets, every buffer allocated at construction: the writer fills its
// private set (write_slot) and publishes it, which swaps it with the shared middle set; the
// reader acquires the newest published set, which swaps its own set with the middle one and
// keeps the acquired set (read-only) until its next acquire. Atomics only: publish and acquire
// are wait-free, never allocate and never lock. A set the reader did not acquire before the next
// publish is replaced (the reader always sees the newest).
//
// One writer and one reader at a time. Both sides claim their end first; across a plugin
// hot-swap the new instance's worker waits (wait_signal) until the old one released it.
// Images are rows packed (stride = width * bytes_per_pixel): 8-bit grey for the colour cameras'
// sets; a depth source's sets carry 16-bit depth and 8-bit BGR images (bytes_per_pixel 2 and 3).
// Each image also carries where its camera stood when it was captured (CameraPose): a camera the
// robot carries moves between sets, so its pose travels with its pixels, in the same buffer.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/assert.h"

namespace crease::frames {

// One image of a frame set: its name (the calibration's, e.g. "cam0") and size, pixels; bytes
// per pixel 1 (8-bit grey, the default), 2 (16-bit depth) or 3 (8-bit BGR).
struct CameraSpec {
  std::string name;
  int width = 0;
  int height = 0;
  int bytes_per_pixel = 1;
  friend bool operator==(const CameraSpec&, const CameraSpec&) = default;
};

inline constexpr std::size_t kMaxImages = 32;  // images of one set (valid_mask bits)

// Where the camera of an image stood at the image's capture, in the world (mm):
//   x_world = rotation * x_camera + translation_mm   (rotation row by row, world-from-camera)
// carried false: the camera is fixed in the world and its calibration says where (rotation and
// translation_mm are not used). A writer whose camera moves (a wrist camera) sets carried and
// the pose of that capture; the reader checks it (a non-finite pose is the writer's bug or a bad
// recording, never trusted).
struct CameraPose {
  bool carried = false;
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double translation_mm[3] = {0, 0, 0};
};

// One buffer of the triple buffer: a frame set and what the writer said about it.
class FrameSet {
 public:
  std::uint64_t sequence = 0;    // channel sequence (1 for the first publish); 0 = never published
  std::uint64_t frame = 0;       // the source's frame index
  std::int64_t stamp_ns = 0;     // CLOCK_MONOTONIC capture time
  std::uint32_t valid_mask = 0;  // bit k: camera k delivered an image in this set

  [[nodiscard]] std::uint8_t* pixels(std::size_t camera) noexcept {
    CREASE_DEBUG_ASSERT(camera < images_.size());
    return images_[camera].get();
  }
  [[nodiscard]] const std::uint8_t* pixels(std::size_t camera) const noexcept {
    CREASE_DEBUG_ASSERT(camera < images_.size());
    return images_[camera].get();
  }
  [[nodiscard]] bool valid(std::size_t camera) const noexcept {
    return ((valid_mask >> camera) & 1u) != 0;
  }
  // Image k's camera pose at this set's capture. The writer sets every image's before publish
  // (a set is reused: a pose not set is the one this buffer carried three publishes ago).
  [[nodiscard]] CameraPose& pose(std::size_t camera) noexcept {
    CREASE_DEBUG_ASSERT(camera < kMaxImages);
    return poses_[camera];
  }
  [[nodiscard]] const CameraPose& pose(std::size_t camera) const noexcept {
    CREASE_DEBUG_ASSERT(camera < kMaxImages);
    return poses_[camera];
  }

 private:
  friend class FrameChannel;
  std::vector<std::unique_ptr<std::uint8_t[]>> images_;
  std::array<CameraPose, kMaxImages> poses_{};  // allocated with the set: 3.3 kB
};

class FrameChannel {
 public:
  static constexpr std::size_t kMaxCameras = kMaxImages;  // valid_mask bits
  // The channel's type as ports list it (its cameras say the rest).
  static constexpr char kTypeName[] = "crease.FrameSet";
  static constexpr std::uint32_t kTypeVersion = 1;

  // Allocates three frame sets (non-RT). Throws ConfigError naming the channel when there are
  // no cameras, more than kMaxCameras, duplicate names or a non-positive size (the cameras
  // come from calibration files).
  FrameChannel(std::string name, std::vector<CameraSpec> cameras);
  FrameChannel(const FrameChannel&) = delete;
  FrameChannel& operator=(const FrameChannel&) = delete;

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] const std::vector<CameraSpec>& cameras() const noexcept { return cameras_; }
  [[nodiscard]] std::size_t image_bytes(std::size_t camera) const noexcept {
    return static_cast<std::size_t>(cameras_[camera].width) *
           static_cast<std::size_t>(cameras_[camera].height) *
           static_cast<std::size_t>(cameras_[camera].bytes_per_pixel);
  }
  [[nodiscard]] std::size_t set_bytes() const noexcept;  // pixels of one frame set, all cameras
  [[nodiscard]] std::uint32_t all_cameras_mask() const noexcept;

  // --- writer end (one holder at a time) ---
  [[nodiscard]] bool try_claim_writer() noexcept;
  void release_writer() noexcept;  // also wakes waiters
  // The writer's private set: fill pixels(k) of the cameras that delivered, then publish.
  [[nodiscard]] FrameSet& write_slot() noexcept { return slots_[writer_]; }
  // Publishes write_slot() as the newest set and wakes waiters. Returns its sequence. Wait-free,
  // no allocation (the wake is a futex call: fine on a worker thread).
  std::uint64_t publish(std::int64_t stamp_ns, std::uint64_t frame,
                        std::uint32_t valid_mask) noexcept;

  // --- reader end (one holder at a time) ---
  [[nodiscard]] bool try_claim_reader() noexcept;
  void release_reader() noexcept;  // also wakes waiters
  // The newest set published since the last acquire, or nullptr when there is none. The set
  // stays the reader's (untouched by the writer) until its next acquire. Wait-free.
  [[nodiscard]] const FrameSet* acquire_newest() noexcept;
  // The reader is done with the set of that sequence (a writer in lockstep waits for it).
  void finish(std::uint64_t sequence) noexcept {
    finished_.store(sequence, std::memory_order_release);
  }

  // --- any thread ---
  [[nodiscard]] std::uint64_t published() const noexcept {
    return published_.load(std::memory_order_acquire);
  }
  // Sequence of the newest set the reader acquired (0 = none).
  [[nodiscard]] std::uint64_t consumed() const noexcept {
    return consumed_.load(std::memory_order_acquire);
  }
  // Sets a publish replaced before the reader acquired them (the reader always takes the
  // newest; these it never saw).
  [[nodiscard]] std::uint64_t overwritten() const noexcept {
    return overwritten_.load(std::memory_order_acquire);
  }
  // Sequence of the newest set the reader finished with (0 = none).
  [[nodiscard]] std::uint64_t finished() const noexcept {
    return finished_.load(std::memory_order_acquire);
  }
  [[nodiscard]] bool reader_claimed() const noexcept {
    return reader_claimed_.load(std::memory_order_acquire);
  }
  [[nodiscard]] bool writer_claimed() const noexcept {
    return writer_claimed_.load(std::memory_order_acquire);
  }

  // Wake-ups for worker threads (non-RT: wait_signal blocks). The signal changes on every
  // publish, release and wake(). Pattern: s = signal(); check the condition; wait_signal(s).
  [[nodiscard]] std::uint64_t signal() const noexcept {
    return signal_.load(std::memory_order_acquire);
  }
  void wait_signal(std::uint64_t seen) const noexcept {
    signal_.wait(seen, std::memory_order_acquire);
  }
  void wake() noexcept;

 private:
  static constexpr std::uint32_t kIndexMask = 3;
  static constexpr std::uint32_t kFresh = 4;  // the middle set was published and not yet acquired

  std::string name_;
  std::vector<CameraSpec> cameras_;
  FrameSet slots_[3];
  std::uint32_t writer_ = 0;  // index of the writer's set (writer end only)
  std::uint32_t reader_ = 1;  // index of the reader's set (reader end only)
  // Each on its own cache line: the writer and the reader both swap with the middle.
  alignas(64) std::atomic<std::uint32_t> middle_{2};
  alignas(64) std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> overwritten_{0};  // written by the writer only
  alignas(64) std::atomic<std::uint64_t> consumed_{0};
  std::atomic<std::uint64_t> finished_{0};
  alignas(64) std::atomic<std::uint64_t> signal_{0};
  std::atomic<bool> writer_claimed_{false};
  std::atomic<bool> reader_claimed_{false};
};

}  // namespace crease::frames
