#include "drivers/host/tactile_reader.h"

#include <pthread.h>
#include <sched.h>

#include "rt/clock.h"
#include "rt/thread_placement.h"

namespace crease::drivers {

TactileReader::TactileReader(std::unique_ptr<SerialIo> io, const TactileHostConfig& cfg, const char* thread_name)
    : io_(std::move(io)), cfg_(cfg), name_(thread_name), queue_(sizeof(Record), kQueueCapacity) {}

TactileReader::~TactileReader() { stop(); }

void TactileReader::start() {
  if (thread_.joinable()) return;
  stop_.store(false, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
}

void TactileReader::stop() {
  if (!thread_.joinable()) return;
  stop_.store(true, std::memory_order_release);
  io_->wake();
  thread_.join();
  fifo_.store(false, std::memory_order_release);
}

void TactileReader::send_start(std::int64_t now_ns) {
  std::uint8_t p[2];
  const std::size_t n = tactile::encode_start(cfg_.rate_hz, p);
  const std::size_t w = serial_encode(tx_seq_++, tactile::kTypeStart, {p, n}, tx_);
  const long put = io_->write({tx_, w});
  if (put > 0 && static_cast<std::size_t>(put) < w) {
    const std::uint8_t zero = 0;  // ends the partial frame so the sensor drops it
    (void)io_->write({&zero, 1});
  }
  if (put == static_cast<long>(w)) started_.store(true, std::memory_order_release);
  last_start_ns_ = now_ns;
}

void TactileReader::run() {
  rt::place_this_thread_non_rt(name_);
  // Real-time where permitted, when it inherited the default policy (a thread made by a loop
  // keeps the loop's; tactile_reader.h says why).
  int inherited = SCHED_OTHER;
  sched_param param{};
  (void)pthread_getschedparam(pthread_self(), &inherited, &param);
  if (inherited == SCHED_OTHER && cfg_.thread_priority > 0) {
    sched_param sp{};
    sp.sched_priority = cfg_.thread_priority;
    fifo_.store(pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0, std::memory_order_release);
  }
  last_start_ns_ = rt::now_ns() - cfg_.start_retry_ns;  // the first Start goes out at once
  while (!stop_.load(std::memory_order_acquire)) {
    std::int64_t now = rt::now_ns();
    // Start while the stream is silent: before the first sample, and after max_age_ns without.
    const bool stale = !any_rx_ || now - last_rx_ns_ > cfg_.max_age_ns;
    if (stale && now - last_start_ns_ >= cfg_.start_retry_ns) send_start(now);
    const long n = io_->read_wait(rx_, kWaitMs);
    if (n <= 0) continue;
    now = rt::now_ns();
    std::size_t pos = 0;
    const auto len = static_cast<std::size_t>(n);
    while (pos < len) {
      SerialFrame f;
      bool got = false;
      pos += deframer_.feed({rx_ + pos, len - pos}, f, &got);
      if (!got) continue;
      Record r;
      if (tactile::decode_sample(f, r.sample) != Decode::ok) continue;
      r.rx_ns = now;
      any_rx_ = true;
      last_rx_ns_ = now;
      (void)queue_.try_push(&r);  // full: dropped and counted by the queue (an overrun)
    }
    framing_errors_.store(deframer_.stats().crc_errors + deframer_.stats().cobs_errors, std::memory_order_relaxed);
  }
}

bool TactileReader::take_rt(std::int64_t now_ns) noexcept {
  bool got = false;
  while (queue_.try_pop(&held_[1 - front_])) {
    front_ = 1 - front_;
    held_[front_].rx_ns = now_ns;
    ++taken_;
    got = true;
  }
  if (got) taken_shared_.store(taken_, std::memory_order_relaxed);
  return got;
}

LinkHealth TactileReader::health(std::int64_t now_ns) const noexcept {
  return tactile_health(cfg_, taken_, held_[front_].rx_ns, framing_errors_.load(std::memory_order_relaxed), now_ns);
}

TactileCounters TactileReader::counters() const noexcept {
  TactileCounters c;
  c.frames = taken_shared_.load(std::memory_order_relaxed);
  c.crc_errors = framing_errors_.load(std::memory_order_relaxed);
  c.overruns = queue_.dropped();
  return c;
}

}  // namespace crease::drivers
