#include "vision_worker.h"

#include <cstring>

namespace crease::vision {

VisionWorker::VisionWorker(std::unique_ptr<CameraSource> source, const MarkerLayout& layout,
                           const DetectorConfig& det, const TriangulationConfig& tri, const std::string& record_dir)
    : source_(std::move(source)),
      pipeline_(source_->cameras(), layout, det, tri),
      result_(std::make_unique<crease::Keypoints>()) {
  if (!record_dir.empty()) recorder_ = std::make_unique<Recorder>(record_dir, source_->cameras());
  const std::size_t n = std::min<std::size_t>(source_->cameras().size(), 32);
  all_mask_ = n == 32 ? 0xffffffffu : (1u << n) - 1u;
  thread_ = std::thread([this] { run(); });
}

VisionWorker::~VisionWorker() {
  // Wait for a frame in flight, then stop the thread.
  int s = state_.load(std::memory_order_acquire);
  while (true) {
    while (s == kRequested || s == kBusy) {
      state_.wait(s, std::memory_order_acquire);
      s = state_.load(std::memory_order_acquire);
    }
    if (state_.compare_exchange_weak(s, kStop, std::memory_order_acq_rel)) break;
  }
  state_.notify_all();
  thread_.join();
}

std::string VisionWorker::error() const {
  return state_.load(std::memory_order_acquire) == kFailed ? error_ : std::string();
}

VisionWorker::Take VisionWorker::take_and_request_rt(crease::Keypoints& out) noexcept {
  Take t = Take::none;
  int s = state_.load(std::memory_order_acquire);
  if (s == kEnded) return Take::ended;
  if (s == kFailed) return Take::failed;
  if (s == kDone) {
    // The worker does not touch result_ until we hand the slot back.
    out.timestamp_ns = result_->timestamp_ns;
    out.frame = result_->frame;
    out.count = result_->count;
    out.cameras_ok = result_->cameras_ok;
    std::memcpy(out.points, result_->points, sizeof(crease::Keypoint) * result_->count);
    t = Take::fresh;
    state_.store(kIdle, std::memory_order_release);
    s = kIdle;
  }
  if (s == kIdle) {
    state_.store(kRequested, std::memory_order_release);
    state_.notify_one();
  }
  return t;
}

void VisionWorker::run() {
  while (true) {
    int s = state_.load(std::memory_order_acquire);
    while (s != kRequested && s != kStop) {
      state_.wait(s, std::memory_order_acquire);
      s = state_.load(std::memory_order_acquire);
    }
    if (s == kStop) return;
    state_.store(kBusy, std::memory_order_release);
    int next = kDone;
    try {
      if (!source_->grab(frame_)) {
        next = kEnded;
      } else {
        if (recorder_) recorder_->write(frame_);
        pipeline_.process(frame_.images, frame_.timestamp_ns, *result_);
      }
    } catch (const std::exception& e) {
      error_ = e.what();
      next = kFailed;
    }
    state_.store(next, std::memory_order_release);
    state_.notify_all();
  }
}

}  // namespace crease::vision
