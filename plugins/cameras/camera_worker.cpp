#include "plugins/cameras/camera_worker.h"

#include <cstring>

#include "core/assert.h"
#include "plugins/camera_rig/images_port.h"

namespace crease::vision {
namespace {

// The OpenCV type of a channel image (frame_channel.h: 1 grey, 2 depth, 3 BGR bytes per pixel).
int mat_type(const crease::frames::CameraSpec& spec) {
  switch (spec.bytes_per_pixel) {
    case 2: return CV_16UC1;
    case 3: return CV_8UC3;
    case 4: return CV_8UC4;
    default: return CV_8UC1;
  }
}

}  // namespace

CameraWorker::CameraWorker(std::unique_ptr<CameraSource> source,
                           std::shared_ptr<crease::frames::FrameChannel> channel,
                           const std::string& record_dir)
    : source_(std::move(source)), channel_(std::move(channel)) {
  // The plugin bound the channel with these cameras (plugins/camera_rig/images_port.h): the
  // registry checked them.
  CREASE_DEMAND(channel_->cameras() == source_->channel_images(),
                "the frame channel does not have this source's cameras");
  if (!record_dir.empty())
    recorder_ = std::make_unique<Recorder>(record_dir, source_->cameras(),
                                           source_->depth_units_mm(), source_->mounts());
  writer_ = channel_->try_claim_writer();  // now if free, so the first request need not wait
  thread_ = std::thread([this] { run(); });
}

CameraWorker::~CameraWorker() {
  // Let a frame in flight finish, then stop the thread (also when it waits for the writer end).
  stop_.store(true, std::memory_order_release);
  source_->cancel();  // a replay waiting for its frame's time returns now
  channel_->wake();
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
  if (writer_) channel_->release_writer();
}

std::string CameraWorker::error() const {
  return state_.load(std::memory_order_acquire) == kFailed ? error_ : std::string();
}

CameraWorker::Take CameraWorker::take_and_request_rt(Published& out, bool request) noexcept {
  Take t = Take::none;
  int s = state_.load(std::memory_order_acquire);
  if (s == kEnded) return Take::ended;
  if (s == kFailed) return Take::failed;
  if (s == kDone) {
    out = published_;  // the worker does not touch it until the slot is idle again
    t = Take::fresh;
    state_.store(kIdle, std::memory_order_release);
    s = kIdle;
  }
  if (s == kIdle && request) {
    state_.store(kRequested, std::memory_order_release);
    state_.notify_one();
  }
  return t;
}

bool CameraWorker::claim_writer() {
  while (!writer_) {
    const std::uint64_t seen = channel_->signal();
    if (stop_.load(std::memory_order_acquire)) return false;
    writer_ = channel_->try_claim_writer();
    if (!writer_) channel_->wait_signal(seen);  // the previous writer releases with a wake
  }
  return true;
}

void CameraWorker::point_at_write_set() {
  // A source that renders (SimSource) writes straight into the channel's write set; what a
  // source delivers elsewhere is copied by copy_into_channel().
  crease::frames::FrameSet& set = channel_->write_slot();
  frame_.images.resize(channel_->cameras().size());
  for (std::size_t k = 0; k < frame_.images.size(); ++k) {
    const auto& spec = channel_->cameras()[k];
    frame_.images[k] = cv::Mat(spec.height, spec.width, mat_type(spec), set.pixels(k));
  }
  frame_.fill_in_place = true;
}

std::uint32_t CameraWorker::copy_into_channel() {
  crease::frames::FrameSet& set = channel_->write_slot();
  std::uint32_t valid = 0;
  // Every image's pose, delivered or not: the set is reused and would keep an old one.
  for (std::size_t k = 0; k < channel_->cameras().size(); ++k)
    set.pose(k) = k < frame_.poses.size() ? frame_.poses[k] : crease::frames::CameraPose{};
  for (std::size_t k = 0; k < channel_->cameras().size() && k < frame_.images.size(); ++k) {
    const cv::Mat& im = frame_.images[k];
    const auto& spec = channel_->cameras()[k];
    if (im.empty() || im.type() != mat_type(spec) || im.cols != spec.width || im.rows != spec.height)
      continue;
    if (im.data == set.pixels(k) && im.isContinuous()) {  // filled in place
      valid |= 1u << k;
      continue;
    }
    const auto row = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.bytes_per_pixel);
    for (int y = 0; y < im.rows; ++y)
      std::memcpy(set.pixels(k) + row * static_cast<std::size_t>(y), im.ptr(y), row);
    valid |= 1u << k;
  }
  return valid;
}

void CameraWorker::run() {
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
      if (!claim_writer()) {
        next = kIdle;  // stopping
      } else {
        point_at_write_set();
        if (!source_->grab(frame_)) {
          next = kEnded;
        } else {
          if (recorder_) recorder_->write(frame_);
          const std::uint32_t valid = copy_into_channel();
          published_.sequence = channel_->publish(frame_.timestamp_ns, frame_.index, valid);
          published_.frame = frame_.index;
          published_.stamp_ns = frame_.timestamp_ns;
          published_.valid_mask = valid;
        }
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
