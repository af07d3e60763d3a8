// RecordingCanBus: records any CanBus to a candump -L log. It wraps the bus: every frame sent
// (as accepted) and every frame received (error frames too) is copied into a fixed ring from
// the RT thread (no allocation; when the ring is full the record is dropped and counted); a
// non-RT thread calls drain_to() to write the lines. One RT user, one draining thread.
// Times: frames are stamped with CLOCK_MONOTONIC (as the bus gives them) and written, as
// `candump -L` does, in wall-clock epoch seconds: monotonic time plus one offset taken at
// construction, so the intervals between lines stay the monotonic ones (replay_candump paces
// by the intervals from the first line) even if the wall clock is stepped while recording.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "drivers/can/can_bus.h"
#include "drivers/can/candump_log.h"

namespace crease::drivers {

class RecordingCanBus final : public CanBus {
 public:
  RecordingCanBus(CanBus& inner, const std::string& interface, std::size_t capacity = 16384);

  [[nodiscard]] SendResult send(const CanFrame& f) noexcept override;
  std::size_t send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept override;
  [[nodiscard]] RecvResult try_receive(RxFrame& out) noexcept override;
  [[nodiscard]] int fd() const noexcept override { return inner_.fd(); }
  [[nodiscard]] BusState state() const noexcept override { return inner_.state(); }
  void restart() noexcept override { inner_.restart(); }
  [[nodiscard]] const CanBusCounters& counters() const noexcept override { return inner_.counters(); }
  [[nodiscard]] int errno_value() const noexcept override { return inner_.errno_value(); }

  // Non-RT: writes every recorded frame to the log; returns how many.
  std::size_t drain_to(CandumpWriter& log);
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }
  // CLOCK_REALTIME - CLOCK_MONOTONIC in ns at construction: what drain_to adds to the stamps.
  [[nodiscard]] std::int64_t epoch_offset_ns() const noexcept { return epoch_offset_ns_; }

 private:
  void record(const CanFrame& f, std::int64_t ts) noexcept;
  CanBus& inner_;
  char interface_[16] = {};
  std::vector<CandumpEntry> ring_;
  alignas(64) std::atomic<std::size_t> head_{0};  // written by the RT side
  alignas(64) std::atomic<std::size_t> tail_{0};  // written by the draining side
  std::atomic<std::uint64_t> dropped_{0};
  std::int64_t epoch_offset_ns_ = 0;
};

}  // namespace crease::drivers
