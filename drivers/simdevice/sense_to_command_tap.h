// SenseToCommandTap: measures, on a simulated hand's side of the bus, how many cycles pass
// between a status the hand sends and the command built from it. It wraps the hand's bus:
// every hand status sent is remembered (its device time), every hand command received is
// matched to the status whose device time it carries (encode_device_time, written by a
// controller such as the hand_echo test plugin). Lag 0: the command answers the newest status
// sent (sensing and command in the same host cycle); lag n: n newer statuses were sent before
// it arrived. The device thread sends and receives; any thread reads the counters.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>

#include "drivers/can/can_bus.h"
#include "drivers/protocol/hand_protocol.h"

namespace crease::drivers::sim {

// Device time in joints 0..2 of a command's targets: 10 bits each, 1 mrad per count (0..1.023
// rad, exact through the protocol's 0.1 mrad unit). 30 bits of device time: 17 minutes.
inline void encode_device_time(std::uint32_t t_us, float* target_rad) noexcept {
  for (int k = 0; k < 3; ++k) target_rad[k] = static_cast<float>((t_us >> (10 * k)) & 1023u) * 1e-3f;
}
[[nodiscard]] inline std::uint32_t decode_device_time(const float* target_rad) noexcept {
  std::uint32_t t = 0;
  for (int k = 0; k < 3; ++k) t |= static_cast<std::uint32_t>(std::lround(target_rad[k] * 1e3f)) << (10 * k);
  return t;
}

class SenseToCommandTap final : public CanBus {
 public:
  static constexpr int kLags = 4;  // lags 0..2 counted apart; 3 = three or more (or unknown)

  SenseToCommandTap(CanBus& inner, std::uint8_t node) noexcept : inner_(inner), node_(node) {}

  [[nodiscard]] SendResult send(const CanFrame& f) noexcept override {
    const SendResult r = inner_.send(f);
    if (r == SendResult::ok) note_sent(f);
    return r;
  }
  std::size_t send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept override {
    const std::size_t n = inner_.send_batch(frames, last);
    for (std::size_t i = 0; i < n; ++i) note_sent(frames[i]);
    return n;
  }
  [[nodiscard]] RecvResult try_receive(RxFrame& out) noexcept override {
    const RecvResult r = inner_.try_receive(out);
    hand::Command c;
    if (r == RecvResult::frame && hand::decode(node_, out.frame, c) == Decode::ok && (c.flags & hand::kCmdEnable)) {
      const std::uint32_t answered = decode_device_time(c.target_rad);
      int lag = kLags - 1;
      for (int back = 0; back < kRing && back < static_cast<int>(sent_); ++back) {
        if ((sent_times_[(sent_ - 1 - back) % kRing] & kMask) == answered) {
          lag = back < kLags - 1 ? back : kLags - 1;
          break;
        }
      }
      lags_[lag].fetch_add(1, std::memory_order_relaxed);
    }
    return r;
  }
  [[nodiscard]] int fd() const noexcept override { return inner_.fd(); }
  [[nodiscard]] BusState state() const noexcept override { return inner_.state(); }
  void restart() noexcept override { inner_.restart(); }
  [[nodiscard]] const CanBusCounters& counters() const noexcept override { return inner_.counters(); }
  [[nodiscard]] int errno_value() const noexcept override { return inner_.errno_value(); }

  // Commands received whose sensing was `lag` cycles old (kLags - 1: that many or more).
  [[nodiscard]] std::uint64_t commands_with_lag(int lag) const noexcept {
    return lags_[lag].load(std::memory_order_relaxed);
  }
  // The most common lag so far (0 when nothing was counted).
  [[nodiscard]] int typical_lag() const noexcept {
    int best = 0;
    for (int k = 1; k < kLags; ++k)
      if (commands_with_lag(k) > commands_with_lag(best)) best = k;
    return best;
  }

 private:
  static constexpr int kRing = 16;
  static constexpr std::uint32_t kMask = (1u << 30) - 1;
  void note_sent(const CanFrame& f) noexcept {
    hand::Status s;
    if (hand::decode(node_, f, s) != Decode::ok) return;
    sent_times_[sent_ % kRing] = s.device_time_us;
    ++sent_;
  }

  CanBus& inner_;
  std::uint8_t node_;
  std::uint32_t sent_times_[kRing] = {};
  std::uint64_t sent_ = 0;  // device thread only
  std::atomic<std::uint64_t> lags_[kLags] = {};
};

}  // namespace crease::drivers::sim
