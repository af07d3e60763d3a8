#include "plugins/cameras/replay_source.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <utility>

#include "core/assert.h"
#include "core/errors.h"
#include "rt/clock.h"
#include "rt/thread_placement.h"

namespace crease::vision {

ReplaySource::ReplaySource(const std::string& dir, std::size_t read_ahead, int decoders)
    : reader_(dir), capacity_(std::max<std::size_t>(read_ahead, 1)) {
  slots_.resize(capacity_);
  ready_.assign(capacity_, 0);
  for (int k = 0; k < std::max(decoders, 1); ++k) decoders_.emplace_back([this, k] { decode_loop(k); });
}

ReplaySource::~ReplaySource() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    cancelled_ = true;
  }
  changed_.notify_all();
  for (std::thread& t : decoders_) t.join();
}

void ReplaySource::cancel() noexcept {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cancelled_ = true;
  }
  changed_.notify_all();
}

void ReplaySource::decode_loop(int k) {
  char name[16];
  std::snprintf(name, sizeof name, "crease-replay-%d", k);
  crease::rt::place_this_thread_non_rt(name);
  while (true) {
    std::size_t i = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return stop_ || claimed_ >= reader_.frames() || claimed_ < next_ + capacity_; });
      if (stop_ || claimed_ >= reader_.frames() || !error_.empty()) return;
      i = claimed_++;
    }
    Frame f;
    try {
      reader_.read(i, f);  // outside the lock: the PNG decoding is the slow part
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = e.what();
      changed_.notify_all();
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      slots_[i % capacity_] = std::move(f);
      ready_[i % capacity_] = 1;
    }
    changed_.notify_all();
  }
}

std::size_t ReplaySource::queued() {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<std::size_t>(std::count(ready_.begin(), ready_.end(), 1));
}

std::int64_t ReplaySource::interval_ns(std::size_t i) const {
  const auto& s = reader_.stamps();
  if (i + 1 < s.size()) return s[i + 1].stamp_ns - s[i].stamp_ns;
  if (i > 0) return s[i].stamp_ns - s[i - 1].stamp_ns;
  return 0;
}

bool ReplaySource::grab(Frame& frame) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (cancelled_ || next_ >= reader_.frames()) return false;
  const auto& stamps = reader_.stamps();
  std::int64_t start = start_ns_.load(std::memory_order_relaxed);
  std::int64_t due = start + (stamps[next_].stamp_ns - stamps[0].stamp_ns);
  if (next_ > 0) {  // not before its time (cancellable: the worker's destructor cancels a wait)
    const std::chrono::steady_clock::time_point due_tp{std::chrono::nanoseconds(due)};
    changed_.wait_until(lock, due_tp, [&] { return cancelled_; });
  }
  const std::size_t slot = next_ % capacity_;
  changed_.wait(lock, [&] { return cancelled_ || ready_[slot] != 0 || !error_.empty(); });  // decoded
  if (!error_.empty() && ready_[slot] == 0) throw crease::Error("replay decoder: " + error_);
  if (cancelled_) return false;
  Frame f = std::move(slots_[slot]);
  ready_[slot] = 0;
  const std::size_t i = next_++;
  lock.unlock();
  changed_.notify_all();  // room for the decoders

  const std::int64_t now = crease::rt::now_ns();
  if (i == 0) {  // the replay starts when its first frame is handed out
    start = due = now;
    first_start_ns_.store(start, std::memory_order_release);
  }
  const std::int64_t interval = interval_ns(i);
  if (interval > 0 && now - due >= interval) {
    // Late: the next frame was due already. The replay's clock holds back by what it lost, so
    // this frame is stamped now and the ones after it keep their recorded intervals from here.
    late_.fetch_add(1, std::memory_order_acq_rel);
    start += now - due;
    due = now;
  }
  start_ns_.store(start, std::memory_order_release);
  // Behind the recording: where this frame is handed out against the unbroken recorded timeline.
  const std::int64_t lag =
      now - (first_start_ns_.load(std::memory_order_relaxed) + (stamps[i].stamp_ns - stamps[0].stamp_ns));
  last_lag_ns_.store(lag, std::memory_order_release);
  if (lag > max_lag_ns_.load(std::memory_order_relaxed)) max_lag_ns_.store(lag, std::memory_order_release);
  last_delivery_ns_.store(now, std::memory_order_release);

  frame.index = f.index;
  frame.timestamp_ns = due;  // re-based: the replay's start + the recorded interval since frame 0
  frame.images.resize(f.images.size());
  for (std::size_t k = 0; k < f.images.size(); ++k) frame.images[k] = std::move(f.images[k]);
  frame.poses = std::move(f.poses);  // a carried camera's recorded pose per image (or none)
  played_.fetch_add(1, std::memory_order_acq_rel);
  return true;
}

}  // namespace crease::vision
