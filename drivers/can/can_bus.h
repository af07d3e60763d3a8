// CanBus: the interface every CAN transport implements (SocketCAN, the user-space mock).
// All calls are non-blocking and RT-safe after construction: no allocation, no locks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "drivers/can/can_frame.h"

namespace crease::drivers {

// Controller error state, as ISO 11898 defines it (plus "stopped" for a closed bus).
enum class BusState : std::uint8_t { error_active, error_warning, error_passive, bus_off, stopped };
[[nodiscard]] const char* to_string(BusState s) noexcept;

enum class SendResult : std::uint8_t {
  ok,
  no_buffers,  // tx queue full (ENOBUFS / EAGAIN): back-pressure, try again next cycle
  bus_off,     // controller is bus-off: nothing is sent until restart()
  error,       // any other failure (see errno_value())
};

enum class RecvResult : std::uint8_t {
  frame,        // a data frame
  error_frame,  // an error frame (CAN_ERR_FLAG); bus state already updated from it
  empty,        // nothing queued
  error,        // the transport failed (see errno_value())
};

struct RxFrame {
  CanFrame frame;
  std::int64_t timestamp_ns = 0;  // CLOCK_MONOTONIC reception time
};

struct CanBusCounters {
  std::uint64_t tx_frames = 0;
  std::uint64_t rx_frames = 0;
  std::uint64_t tx_no_buffers = 0;
  std::uint64_t rx_error_frames = 0;
  std::uint64_t bus_off_events = 0;
};

class CanBus {
 public:
  virtual ~CanBus() = default;
  // Queues one frame for transmission. RT-safe.
  [[nodiscard]] virtual SendResult send(const CanFrame& f) noexcept = 0;
  // Queues frames in order with as few system calls as the transport allows; stops at the
  // first frame not accepted. Returns how many were queued; *last gets the result of the
  // last attempt. RT-safe.
  virtual std::size_t send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept {
    SendResult r = SendResult::ok;
    std::size_t n = 0;
    for (const CanFrame& f : frames) {
      if ((r = send(f)) != SendResult::ok) break;
      ++n;
    }
    if (last) *last = r;
    return n;
  }
  // Takes the next received frame if any. RT-safe.
  [[nodiscard]] virtual RecvResult try_receive(RxFrame& out) noexcept = 0;
  // A file descriptor that polls readable when try_receive may return something.
  [[nodiscard]] virtual int fd() const noexcept = 0;
  [[nodiscard]] virtual BusState state() const noexcept = 0;
  // Leaves bus-off (the controller restarts, like `ip link set canX type can restart`).
  virtual void restart() noexcept = 0;
  [[nodiscard]] virtual const CanBusCounters& counters() const noexcept = 0;
  [[nodiscard]] virtual int errno_value() const noexcept = 0;
};

// Bus state implied by a SocketCAN error frame (CAN_ERR_CRTL / CAN_ERR_BUSOFF / restarted),
// given the state before it. Shared by SocketCanBus and MockCanBus.
[[nodiscard]] BusState bus_state_after_error_frame(BusState before, const CanFrame& err) noexcept;

// Accounts one received frame: an error frame moves state (counting a new bus-off) and is
// counted in rx_error_frames (-> error_frame); a data frame in rx_frames (-> frame). Shared by
// SocketCanBus and MockCanBus. RT-safe.
[[nodiscard]] RecvResult account_received(const CanFrame& f, BusState& state, CanBusCounters& counters) noexcept;

// Builds the error frame a controller reports for entering a state (for mocks and tests).
[[nodiscard]] CanFrame make_error_frame_for_state(BusState s) noexcept;

}  // namespace crease::drivers
