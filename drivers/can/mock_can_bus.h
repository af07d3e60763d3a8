// MockCanBus: one node on a user-space CAN bus served by a MockCanBroker (same process or
// another). Behaves like a raw CAN socket: non-blocking I/O, a pollable fd, error frames that
// move the bus state, and a transmit queue of kTxQueueLen frames modelled at the bus bitrate:
// a full queue gives SendResult::no_buffers, as ENOBUFS does on a real socket.
// Frames travel through shared-memory rings (mock_wire.h): send and try_receive cost no system
// call, except that a send wakes the broker thread when it sleeps (one eventfd write). fd()
// polls readable when frames arrived; once try_receive has reported empty, a second empty call
// in a row re-arms it (one system call), so a cyclic reader that stops at the first empty
// costs none, and a poller sees at most one spurious wake-up.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "drivers/can/can_bus.h"

namespace crease::drivers::mockwire {
struct NodeShm;
struct ReactorShm;
}  // namespace crease::drivers::mockwire

namespace crease::drivers {

struct MockCanBusConfig {
  std::string bus;                        // broker's bus name
  std::uint32_t node_id = 0;              // identifies this node to the broker (faults, bus-off)
  std::uint32_t nominal_bps = 1'000'000;  // for the tx queue model; 0 = unlimited
  std::uint32_t data_bps = 5'000'000;
  // Besides this process's user (and root), a broker run by a member of this group is
  // trusted (mock_access.h); empty: the environment variable CREASE_CAN_GROUP, or nobody else.
  std::string group;
};

class MockCanBus final : public CanBus {
 public:
  static constexpr int kTxQueueLen = 10;  // Linux default txqueuelen of a CAN netdev

  // Connects to the broker. Throws std::runtime_error naming the bus if none serves it, if the
  // broker runs as a user this node does not trust, or if the broker refuses this node's user.
  explicit MockCanBus(MockCanBusConfig cfg);
  ~MockCanBus() override;
  MockCanBus(const MockCanBus&) = delete;
  MockCanBus& operator=(const MockCanBus&) = delete;

  [[nodiscard]] SendResult send(const CanFrame& f) noexcept override;
  // One copy into the shared ring for the whole batch, at most one wake-up of the broker.
  std::size_t send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept override;
  [[nodiscard]] RecvResult try_receive(RxFrame& out) noexcept override;
  [[nodiscard]] int fd() const noexcept override { return fd_; }
  [[nodiscard]] BusState state() const noexcept override { return state_; }
  void restart() noexcept override;
  [[nodiscard]] const CanBusCounters& counters() const noexcept override { return counters_; }
  [[nodiscard]] int errno_value() const noexcept override { return errno_; }
  // How many sends (and restarts) found the broker thread asleep and woke it (a system call).
  [[nodiscard]] std::uint64_t broker_wakeups() const noexcept { return broker_wakeups_; }

 private:
  MockCanBusConfig cfg_;
  int fd_ = -1;           // connection to the broker: doorbells, hang-up
  int doorbell_fd_ = -1;  // the broker thread's eventfd
  mockwire::NodeShm* shm_ = nullptr;
  mockwire::ReactorShm* reactor_ = nullptr;
  BusState state_ = BusState::error_active;
  CanBusCounters counters_;
  int errno_ = 0;
  // Completion times (CLOCK_MONOTONIC ns) of the frames in the modelled tx queue (a ring).
  std::array<std::int64_t, kTxQueueLen> tx_done_{};
  int tx_head_ = 0;
  std::int64_t tx_free_at_ = 0;
  std::uint64_t broker_wakeups_ = 0;
  bool rx_empty_once_ = false;  // the last try_receive reported empty
  void note_sent(const CanFrame& f, std::int64_t now) noexcept;
  void wake_broker() noexcept;
  [[nodiscard]] bool rearm_rx() noexcept;  // drains doorbells; false if the broker is gone
  void close_all() noexcept;
};

}  // namespace crease::drivers
