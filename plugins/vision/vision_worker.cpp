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
    : pipeline_(cameras, layout, det, tri, camera_threads),
      result_(std::make_unique<crease::Keypoints>()),
      images_(cameras.size()),
      worker_(std::move(channel), sizeof(crease::Keypoints)) {
  // The plugin bound the channel with these cameras (plugins/camera_rig/images_port.h): the
  // registry checked them.
  CREASE_DEMAND(worker_.channel().cameras() == channel_specs(cameras), "the frame channel does not have these cameras");
  worker_.start([this](const crease::frames::FrameSet& set) { process(set); }, result_.get());
}

VisionWorker::~VisionWorker() { worker_.stop(); }

VisionWorker::ProcessTimes VisionWorker::process_times() const noexcept {
  ProcessTimes t;
  t.count = worker_.sets_processed();  // the times below are at least this count's (acquire)
  t.last_ns = last_ns_.load(std::memory_order_relaxed);
  t.max_ns = max_ns_.load(std::memory_order_relaxed);
  t.sum_ns = sum_ns_.load(std::memory_order_relaxed);
  return t;
}

void VisionWorker::process(const crease::frames::FrameSet& set) {
  const auto& specs = worker_.channel().cameras();
  for (std::size_t k = 0; k < images_.size(); ++k) {
    // A header over the channel's buffer: no copy. The pipeline only reads it.
    images_[k] = set.valid(k) ? cv::Mat(specs[k].height, specs[k].width, CV_8UC1,
                                        const_cast<std::uint8_t*>(set.pixels(k)))
                              : cv::Mat();
  }
  const std::int64_t t0 = crease::rt::now_ns();
  pipeline_.process(images_, set.stamp_ns, *result_);
  const std::int64_t took = crease::rt::now_ns() - t0;
  last_ns_.store(took, std::memory_order_relaxed);
  max_ns_.store(std::max(max_ns_.load(std::memory_order_relaxed), took), std::memory_order_relaxed);
  sum_ns_.store(sum_ns_.load(std::memory_order_relaxed) + took, std::memory_order_relaxed);
}

}  // namespace crease::vision
