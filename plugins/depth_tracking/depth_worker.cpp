#include "plugins/depth_tracking/depth_worker.h"

#include "core/assert.h"

namespace crease::depth {

DepthWorker::DepthWorker(std::shared_ptr<crease::frames::FrameChannel> channel,
                         const std::vector<vision::DepthCamera>& cameras,
                         const TrackerParams& params)
    : model_buf_(std::make_unique<crease::SheetState>()),
      result_(std::make_unique<crease::DepthTargets>()),
      depth_(cameras.size()),
      bgr_(cameras.size()),
      poses_(cameras.size()),
      worker_(std::move(channel), sizeof(crease::DepthTargets)) {
  CREASE_DEMAND(worker_.channel().cameras() == vision::depth_channel_specs(vision::cameras_of(cameras)),
                "the frame channel does not have these depth cameras");
  tracker_.configure(params, cameras);
  worker_.start([this](const crease::frames::FrameSet& set) { process(set); }, result_.get());
}

DepthWorker::~DepthWorker() { worker_.stop(); }

void DepthWorker::process(const crease::frames::FrameSet& set) {
  const auto& specs = worker_.channel().cameras();
  for (std::size_t k = 0; k < depth_.size(); ++k) {
    const auto& ds = specs[2 * k];
    const auto& cs = specs[2 * k + 1];
    const bool ok = set.valid(2 * k) && set.valid(2 * k + 1);
    // Headers over the channel's buffers: no copy; the tracker only reads them.
    depth_[k] = ok ? cv::Mat(ds.height, ds.width, CV_16UC1, const_cast<std::uint8_t*>(set.pixels(2 * k)))
                   : cv::Mat();
    bgr_[k] = ok ? cv::Mat(cs.height, cs.width, CV_8UC3, const_cast<std::uint8_t*>(set.pixels(2 * k + 1)))
                 : cv::Mat();
    poses_[k] = set.pose(2 * k);  // where the camera was at this capture (its depth image's)
  }
  if (!model_.read(model_buf_.get(), 0).has_data()) model_buf_->nodes_u = model_buf_->nodes_v = 0;
  (void)tracker_.process(depth_, bgr_, *model_buf_, set.stamp_ns, set.frame, *result_, poses_);
  views_.store(tracker_.views(), std::memory_order_release);
  bad_pose_views_.store(tracker_.bad_pose_views(), std::memory_order_release);
}

}  // namespace crease::depth
