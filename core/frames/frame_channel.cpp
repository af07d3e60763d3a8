#include "core/frames/frame_channel.h"

#include <set>

#include "core/assert.h"

namespace crease::frames {

FrameChannel::FrameChannel(std::string name, std::vector<CameraSpec> cameras)
    : name_(std::move(name)), cameras_(std::move(cameras)) {
  require_input(!cameras_.empty(), "frame channel '" + name_ + "': no cameras");
  require_input(cameras_.size() <= kMaxCameras, "frame channel '" + name_ + "': " +
                                                    std::to_string(cameras_.size()) +
                                                    " cameras, at most " +
                                                    std::to_string(kMaxCameras));
  std::set<std::string> names;
  for (const CameraSpec& c : cameras_) {
    require_input(c.width > 0 && c.height > 0,
                  "frame channel '" + name_ + "': camera '" + c.name + "' has size " +
                      std::to_string(c.width) + "x" + std::to_string(c.height));
    require_input(c.bytes_per_pixel >= 1 && c.bytes_per_pixel <= 4,
                  "frame channel '" + name_ + "': camera '" + c.name + "' has " +
                      std::to_string(c.bytes_per_pixel) + " bytes per pixel (1 to 4)");
    require_input(names.insert(c.name).second,
                  "frame channel '" + name_ + "': camera '" + c.name + "' listed twice");
  }
  for (FrameSet& s : slots_) {
    for (std::size_t k = 0; k < cameras_.size(); ++k) {
      s.images_.push_back(std::make_unique<std::uint8_t[]>(image_bytes(k)));  // zeroed: touched now
    }
  }
}

std::size_t FrameChannel::set_bytes() const noexcept {
  std::size_t n = 0;
  for (std::size_t k = 0; k < cameras_.size(); ++k) n += image_bytes(k);
  return n;
}

std::uint32_t FrameChannel::all_cameras_mask() const noexcept {
  const std::size_t n = cameras_.size();
  return n >= 32 ? 0xffffffffu : (1u << n) - 1u;
}

bool FrameChannel::try_claim_writer() noexcept {
  bool expected = false;
  return writer_claimed_.compare_exchange_strong(expected, true, std::memory_order_acq_rel);
}

void FrameChannel::release_writer() noexcept {
  writer_claimed_.store(false, std::memory_order_release);
  wake();
}

bool FrameChannel::try_claim_reader() noexcept {
  bool expected = false;
  return reader_claimed_.compare_exchange_strong(expected, true, std::memory_order_acq_rel);
}

void FrameChannel::release_reader() noexcept {
  reader_claimed_.store(false, std::memory_order_release);
  wake();
}

void FrameChannel::wake() noexcept {
  signal_.fetch_add(1, std::memory_order_acq_rel);
  signal_.notify_all();
}

std::uint64_t FrameChannel::publish(std::int64_t stamp_ns, std::uint64_t frame,
                                    std::uint32_t valid_mask) noexcept {
  FrameSet& s = slots_[writer_];
  const std::uint64_t seq =
      published_.load(std::memory_order_relaxed) + 1;  // only the writer bumps it
  s.sequence = seq;
  s.frame = frame;
  s.stamp_ns = stamp_ns;
  s.valid_mask = valid_mask & all_cameras_mask();
  // Release: the pixels and header above; acquire: the set we get back was released by the
  // reader (it no longer reads it).
  const std::uint32_t was = middle_.exchange(writer_ | kFresh, std::memory_order_acq_rel);
  writer_ = was & kIndexMask;
  if ((was & kFresh) != 0) {  // the set we took back was published and never acquired
    overwritten_.store(overwritten_.load(std::memory_order_relaxed) + 1,
                       std::memory_order_release);
  }
  published_.store(seq, std::memory_order_release);
  wake();
  return seq;
}

const FrameSet* FrameChannel::acquire_newest() noexcept {
  if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return nullptr;
  reader_ = middle_.exchange(reader_, std::memory_order_acq_rel) & kIndexMask;
  const FrameSet& s = slots_[reader_];
  consumed_.store(s.sequence, std::memory_order_release);
  return &s;
}

}  // namespace crease::frames
