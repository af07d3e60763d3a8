#include "drivers/can/recording_can_bus.h"

#include <time.h>

#include <cstring>
#include <stdexcept>

#include "rt/clock.h"

namespace crease::drivers {
RecordingCanBus::RecordingCanBus(CanBus& inner, const std::string& interface, std::size_t capacity)
    : inner_(inner), ring_(capacity) {
  if (interface.empty() || interface.size() >= sizeof(interface_) || capacity < 2) {
    throw std::invalid_argument("recording CAN bus: interface name '" + interface + "' must be 1..15 characters");
  }
  std::memcpy(interface_, interface.data(), interface.size());
  // The offset between the clocks, read between two monotonic reads (the tightest pair of
  // three tries), so it is off by at most the time of one clock read.
  std::int64_t best = -1;
  for (int i = 0; i < 3; ++i) {
    timespec a{}, w{}, b{};
    clock_gettime(CLOCK_MONOTONIC, &a);
    clock_gettime(CLOCK_REALTIME, &w);
    clock_gettime(CLOCK_MONOTONIC, &b);
    const auto ns = [](const timespec& t) { return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec; };
    const std::int64_t span = ns(b) - ns(a);
    if (best < 0 || span < best) {
      best = span;
      epoch_offset_ns_ = ns(w) - (ns(a) + span / 2);
    }
  }
}

void RecordingCanBus::record(const CanFrame& f, std::int64_t ts) noexcept {
  const std::size_t head = head_.load(std::memory_order_relaxed);
  const std::size_t next = (head + 1) % ring_.size();
  if (next == tail_.load(std::memory_order_acquire)) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  CandumpEntry& e = ring_[head];
  e.timestamp_ns = ts;
  std::memcpy(e.interface, interface_, sizeof(e.interface));
  e.frame = f;
  head_.store(next, std::memory_order_release);
}

SendResult RecordingCanBus::send(const CanFrame& f) noexcept {
  const SendResult r = inner_.send(f);
  if (r == SendResult::ok) record(f, rt::now_ns());
  return r;
}

std::size_t RecordingCanBus::send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept {
  const std::size_t n = inner_.send_batch(frames, last);
  const std::int64_t ts = rt::now_ns();
  for (std::size_t i = 0; i < n; ++i) record(frames[i], ts);
  return n;
}

RecvResult RecordingCanBus::try_receive(RxFrame& out) noexcept {
  const RecvResult r = inner_.try_receive(out);
  if (r == RecvResult::frame || r == RecvResult::error_frame) record(out.frame, out.timestamp_ns);
  return r;
}

std::size_t RecordingCanBus::drain_to(CandumpWriter& log) {
  std::size_t n = 0;
  std::size_t tail = tail_.load(std::memory_order_relaxed);
  while (tail != head_.load(std::memory_order_acquire)) {
    CandumpEntry e = ring_[tail];
    e.timestamp_ns += epoch_offset_ns_;
    log.write(e);
    tail = (tail + 1) % ring_.size();
    tail_.store(tail, std::memory_order_release);
    ++n;
  }
  return n;
}

}  // namespace crease::drivers
