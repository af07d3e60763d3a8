#include "plugins/vision/vision_worker.h"

#include <algorithm>

#include "core/assert.h"

#include "plugins/camera_rig/images_port.h"
#include "rt/clock.h"

namespace crease::vision {

VisionWorker::VisionWorker(std::shared_ptr<crease::frames::FrameChannel> channel,
                           std::vector<Camera> cameras, const MarkerLayout& layout,
                           const DetectorConfig& det, const TriangulationConfig& tri,
                           int camera_threads)
    : channel_(std::move(channel)),
      pipeline_(cameras, layout, det, tri, camera_threads),
      result_(std::make_unique<crease::Keypoints>()),
      images_(cameras.size()) {
  // The plugin bound the channel with these cameras (plugins/camera_rig/images_port.h): the
  // registry checked them.
  CREASE_DEMAND(channel_->cameras() == channel_specs(cameras), "the frame channel does not have these cameras");
  reader_ = channel_->try_claim_reader();
  thread_ = std::thread([this] { run(); });
}

VisionWorker::~VisionWorker() {
  stop_.store(true, std::memory_order_release);
  channel_->wake();
  thread_.join();
  if (reader_) channel_->release_reader();
}

std::string VisionWorker::error() const {
  return failed_.load(std::memory_order_acquire) ? error_ : std::string();
}

VisionWorker::Take VisionWorker::take_rt(crease::Keypoints& out) noexcept {
  if (failed_.load(std::memory_order_acquire)) return Take::failed;
  if (results_.sequence() == taken_) return Take::none;
  const crease::rt::ReadInfo info = results_.read(&out, taken_);
  if (!info.is_new()) return Take::none;
  taken_ = info.seq;
  return Take::fresh;
}

bool VisionWorker::claim_reader() {
  while (!reader_) {
    const std::uint64_t seen = channel_->signal();
    if (stop_.load(std::memory_order_acquire)) return false;
    reader_ = channel_->try_claim_reader();
    if (!reader_) channel_->wait_signal(seen);  // the previous reader releases with a wake
  }
  return true;
}

VisionWorker::ProcessTimes VisionWorker::process_times() const noexcept {
  ProcessTimes t;
  t.count = processed_.load(std::memory_order_acquire);  // the times below are at least this count's
  t.last_ns = last_ns_.load(std::memory_order_relaxed);
  t.max_ns = max_ns_.load(std::memory_order_relaxed);
  t.sum_ns = sum_ns_.load(std::memory_order_relaxed);
  return t;
}

void VisionWorker::run() {
  if (!claim_reader()) return;
  try {
    while (true) {
      // Read the signal before looking: a publish after this changes it, so the wait returns.
      const std::uint64_t seen = channel_->signal();
      if (stop_.load(std::memory_order_acquire)) return;
      const crease::frames::FrameSet* set = channel_->acquire_newest();
      if (set == nullptr) {
        channel_->wait_signal(seen);
        continue;
      }
      for (std::size_t k = 0; k < images_.size(); ++k) {
        const auto& spec = channel_->cameras()[k];
        // A header over the channel's buffer: no copy. The pipeline only reads it.
        images_[k] = set->valid(k) ? cv::Mat(spec.height, spec.width, CV_8UC1,
                                             const_cast<std::uint8_t*>(set->pixels(k)))
                                   : cv::Mat();
      }
      const std::int64_t t0 = crease::rt::now_ns();
      pipeline_.process(images_, set->stamp_ns, *result_);
      const std::int64_t took = crease::rt::now_ns() - t0;
      last_ns_.store(took, std::memory_order_relaxed);
      max_ns_.store(std::max(max_ns_.load(std::memory_order_relaxed), took), std::memory_order_relaxed);
      sum_ns_.store(sum_ns_.load(std::memory_order_relaxed) + took, std::memory_order_relaxed);
      results_.write(result_.get(), set->stamp_ns);
      processed_.fetch_add(1, std::memory_order_release);
      channel_->finish(set->sequence);  // a source in lockstep may grab the next frame
    }
  } catch (const std::exception& e) {
    error_ = e.what();
    failed_.store(true, std::memory_order_release);
    channel_->release_reader();  // a source in lockstep must not wait for a reader that stopped
    reader_ = false;
  }
}

}  // namespace crease::vision
