#include "plugins/depth_tracking/depth_worker.h"

#include "core/assert.h"

namespace crease::depth {

DepthWorker::DepthWorker(std::shared_ptr<crease::frames::FrameChannel> channel,
                         const std::vector<vision::DepthCamera>& cameras, const TrackerParams& params)
    : channel_(std::move(channel)),
      model_buf_(std::make_unique<crease::SheetState>()),
      result_(std::make_unique<crease::DepthTargets>()),
      depth_(cameras.size()),
      bgr_(cameras.size()) {
  CREASE_DEMAND(channel_->cameras() == vision::depth_channel_specs(vision::cameras_of(cameras)),
                "the frame channel does not have these depth cameras");
  tracker_.configure(params, cameras);
  reader_ = channel_->try_claim_reader();
  thread_ = std::thread([this] { run(); });
}

DepthWorker::~DepthWorker() {
  stop_.store(true, std::memory_order_release);
  channel_->wake();
  thread_.join();
  if (reader_) channel_->release_reader();
}

std::string DepthWorker::error() const {
  return failed_.load(std::memory_order_acquire) ? error_ : std::string();
}

DepthWorker::Take DepthWorker::take_rt(crease::DepthTargets& out) noexcept {
  if (failed_.load(std::memory_order_acquire)) return Take::failed;
  if (results_.sequence() == taken_) return Take::none;
  const crease::rt::ReadInfo info = results_.read(&out, taken_);
  if (!info.is_new()) return Take::none;
  taken_ = info.seq;
  return Take::fresh;
}

bool DepthWorker::claim_reader() {
  while (!reader_) {
    const std::uint64_t seen = channel_->signal();
    if (stop_.load(std::memory_order_acquire)) return false;
    reader_ = channel_->try_claim_reader();
    if (!reader_) channel_->wait_signal(seen);
  }
  return true;
}

void DepthWorker::run() {
  if (!claim_reader()) return;
  try {
    while (true) {
      const std::uint64_t seen = channel_->signal();
      if (stop_.load(std::memory_order_acquire)) return;
      const crease::frames::FrameSet* set = channel_->acquire_newest();
      if (set == nullptr) {
        channel_->wait_signal(seen);
        continue;
      }
      const auto& specs = channel_->cameras();
      for (std::size_t k = 0; k < depth_.size(); ++k) {
        const auto& ds = specs[2 * k];
        const auto& cs = specs[2 * k + 1];
        const bool ok = set->valid(2 * k) && set->valid(2 * k + 1);
        // Headers over the channel's buffers: no copy; the tracker only reads them.
        depth_[k] = ok ? cv::Mat(ds.height, ds.width, CV_16UC1, const_cast<std::uint8_t*>(set->pixels(2 * k)))
                       : cv::Mat();
        bgr_[k] = ok ? cv::Mat(cs.height, cs.width, CV_8UC3, const_cast<std::uint8_t*>(set->pixels(2 * k + 1)))
                     : cv::Mat();
      }
      if (!model_.read(model_buf_.get(), 0).has_data()) model_buf_->nodes_u = model_buf_->nodes_v = 0;
      (void)tracker_.process(depth_, bgr_, *model_buf_, set->stamp_ns, set->frame, *result_);
      results_.write(result_.get(), set->stamp_ns);
      processed_.fetch_add(1, std::memory_order_release);
      channel_->finish(set->sequence);
    }
  } catch (const std::exception& e) {
    error_ = e.what();
    failed_.store(true, std::memory_order_release);
    channel_->release_reader();
    reader_ = false;
  }
}

}  // namespace crease::depth
