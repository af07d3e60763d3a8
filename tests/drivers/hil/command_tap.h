// CommandTap: the device side's view of the commands a driver sends. It wraps the simulated
// device's bus and decodes every command frame the device receives (Command: the hand's or the
// arm's protocol command). It counts frames equal to the expected command (matching) and, once
// armed, frames that differ from it and frames whose targets are all zero (a driver that lost
// its command). Frames of the driver's safe or hold state (safe(cmd): the hand disabled, the
// arm not in operation, sent when a stalled machine let a watchdog trip) are no command: they
// are counted apart and never as differing or zero. The device thread receives; any thread
// reads the counters.
#pragma once

#include <atomic>
#include <cstdint>

#include "drivers/can/can_bus.h"
#include "drivers/protocol/arm_protocol.h"
#include "drivers/protocol/hand_protocol.h"

namespace crease::drivers::testing {

template <class Command>
class CommandTap final : public CanBus {
 public:
  // match(cmd): the frame carries the expected command; zero(cmd): every target is 0;
  // safe(cmd): a safe-state frame (none when null).
  using Test = bool (*)(const Command&);
  CommandTap(CanBus& inner, std::uint8_t node, Test match, Test zero, Test safe = nullptr) noexcept
      : inner_(inner), node_(node), match_(match), zero_(zero), safe_(safe) {}

  [[nodiscard]] SendResult send(const CanFrame& f) noexcept override { return inner_.send(f); }
  std::size_t send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept override {
    return inner_.send_batch(frames, last);
  }
  [[nodiscard]] RecvResult try_receive(RxFrame& out) noexcept override {
    const RecvResult r = inner_.try_receive(out);
    Command c;
    if (r == RecvResult::frame && decode(node_, out.frame, c) == Decode::ok) {
      const bool armed = armed_.load(std::memory_order_acquire);
      if (safe_ != nullptr && safe_(c)) {
        if (armed) safe.fetch_add(1, std::memory_order_relaxed);
      } else {
        if (match_(c)) matching.fetch_add(1, std::memory_order_relaxed);
        if (armed && !match_(c)) differing.fetch_add(1, std::memory_order_relaxed);
        if (armed && zero_(c)) zeros.fetch_add(1, std::memory_order_relaxed);
      }
      total.fetch_add(1, std::memory_order_relaxed);
    }
    return r;
  }
  [[nodiscard]] int fd() const noexcept override { return inner_.fd(); }
  [[nodiscard]] BusState state() const noexcept override { return inner_.state(); }
  void restart() noexcept override { inner_.restart(); }
  [[nodiscard]] const CanBusCounters& counters() const noexcept override { return inner_.counters(); }
  [[nodiscard]] int errno_value() const noexcept override { return inner_.errno_value(); }

  // From now on, differing and zero frames are counted.
  void arm() noexcept { armed_.store(true, std::memory_order_release); }

  std::atomic<std::uint64_t> matching{0}, differing{0}, zeros{0}, safe{0}, total{0};

 private:
  CanBus& inner_;
  std::uint8_t node_;
  Test match_, zero_, safe_;
  std::atomic<bool> armed_{false};
};

}  // namespace crease::drivers::testing
