// MockCanBus: one node on a user-space CAN bus served by a MockCanBroker (same process or
// another). Behaves like a raw CAN socket: record boundaries, non-blocking I/O, a pollable fd,
// error frames that move the bus state, and a transmit queue of kTxQueueLen frames modelled at
// the bus bitrate: a full queue gives SendResult::no_buffers, as ENOBUFS does on a real socket.
// Receiving takes up to 16 records per recvmmsg(); once a partial batch is drained, one
// try_receive reports empty without a system call (poll the fd or call again to see newer
// frames), so a cyclic reader costs one system call per cycle.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "drivers/can/can_bus.h"

namespace crease::drivers {

struct MockCanBusConfig {
  std::string bus;                        // broker's bus name
  std::uint32_t node_id = 0;              // identifies this node to the broker (faults, bus-off)
  std::uint32_t nominal_bps = 1'000'000;  // for the tx queue model; 0 = unlimited
  std::uint32_t data_bps = 5'000'000;
};

class MockCanBus final : public CanBus {
 public:
  static constexpr int kTxQueueLen = 10;  // Linux default txqueuelen of a CAN netdev

  // Connects to the broker. Throws std::runtime_error naming the bus if none serves it.
  explicit MockCanBus(MockCanBusConfig cfg);
  ~MockCanBus() override;
  MockCanBus(const MockCanBus&) = delete;
  MockCanBus& operator=(const MockCanBus&) = delete;

  [[nodiscard]] SendResult send(const CanFrame& f) noexcept override;
  // One sendmmsg() for the whole batch.
  std::size_t send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept override;
  [[nodiscard]] RecvResult try_receive(RxFrame& out) noexcept override;
  [[nodiscard]] int fd() const noexcept override { return fd_; }
  [[nodiscard]] BusState state() const noexcept override { return state_; }
  void restart() noexcept override;
  [[nodiscard]] const CanBusCounters& counters() const noexcept override { return counters_; }
  [[nodiscard]] int errno_value() const noexcept override { return errno_; }

 private:
  MockCanBusConfig cfg_;
  int fd_ = -1;
  BusState state_ = BusState::error_active;
  CanBusCounters counters_;
  int errno_ = 0;
  // Completion times (CLOCK_MONOTONIC ns) of the frames in the modelled tx queue (a ring).
  std::array<std::int64_t, kTxQueueLen> tx_done_{};
  int tx_head_ = 0;
  std::int64_t tx_free_at_ = 0;
  // Receive ring filled by one recvmmsg() when empty (records of mock_wire.h, 88 bytes each).
  static constexpr int kRxBatch = 16;
  alignas(8) std::uint8_t rx_records_[kRxBatch][88] = {};
  int rx_pos_ = 0, rx_count_ = 0;
  bool rx_partial_ = false;
  [[nodiscard]] bool tx_queue_full(std::int64_t now) const noexcept;
  void note_sent(const CanFrame& f, std::int64_t now) noexcept;
};

}  // namespace crease::drivers
