#include "core/frames/frame_set_worker.h"

#include <exception>
#include <utility>

#include "core/assert.h"

namespace crease::frames {

FrameSetWorker::FrameSetWorker(std::shared_ptr<FrameChannel> channel, std::size_t result_bytes)
    : channel_(std::move(channel)), results_(result_bytes) {}

FrameSetWorker::~FrameSetWorker() { stop(); }

void FrameSetWorker::start(Process process, const void* result) {
  CREASE_DEBUG_ASSERT(!thread_.joinable() && !stop_.load());  // started once, before any stop
  process_ = std::move(process);
  result_ = result;
  reader_ = channel_->try_claim_reader();
  thread_ = std::thread([this] { run(); });
}

void FrameSetWorker::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) {
    channel_->wake();
    thread_.join();
  }
  if (reader_) {
    channel_->release_reader();
    reader_ = false;
  }
}

std::string FrameSetWorker::error() const {
  return failed_.load(std::memory_order_acquire) ? error_ : std::string();
}

FrameSetWorker::Take FrameSetWorker::take_rt(void* out) noexcept {
  if (failed_.load(std::memory_order_acquire)) return Take::failed;
  if (results_.sequence() == taken_) return Take::none;
  const crease::rt::ReadInfo info = results_.read(out, taken_);
  if (!info.is_new()) return Take::none;
  taken_ = info.seq;
  return Take::fresh;
}

bool FrameSetWorker::claim_reader() {
  while (!reader_) {
    const std::uint64_t seen = channel_->signal();
    if (stop_.load(std::memory_order_acquire)) return false;
    reader_ = channel_->try_claim_reader();
    if (!reader_) channel_->wait_signal(seen);  // the previous reader releases with a wake
  }
  return true;
}

void FrameSetWorker::run() {
  if (!claim_reader()) return;
  try {
    while (true) {
      // Read the signal before looking: a publish after this changes it, so the wait returns.
      const std::uint64_t seen = channel_->signal();
      if (stop_.load(std::memory_order_acquire)) return;
      const FrameSet* set = channel_->acquire_newest();
      if (set == nullptr) {
        channel_->wait_signal(seen);
        continue;
      }
      process_(*set);
      results_.write(result_, set->stamp_ns);
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

}  // namespace crease::frames
