// SocketCanBus: a raw AF_CAN socket (Linux SocketCAN) with CAN FD, receive filters, error
// frames turned into bus state, kernel receive timestamps, and ENOBUFS as back-pressure.
// Bus-off is held (sends refused) until restart(), which asks the kernel to restart the
// controller (needs CAP_NET_ADMIN; otherwise it waits for CAN_ERR_RESTARTED from an automatic
// restart-ms restart).
#pragma once

#include <span>
#include <vector>
#include <string>

#include "drivers/can/can_bus.h"

namespace crease::drivers {

struct CanFilter {
  std::uint32_t id;
  std::uint32_t mask;
};

struct SocketCanConfig {
  std::string interface;         // e.g. "can0"
  bool fd = true;                // enable CAN_RAW_FD_FRAMES
  std::vector<CanFilter> filters;  // empty: receive everything
  bool loopback_own = false;     // CAN_RAW_RECV_OWN_MSGS
};

class SocketCanBus final : public CanBus {
 public:
  // Opens and binds the socket. Throws std::system_error naming the interface on failure
  // (errc::address_family_not_supported where the kernel has no AF_CAN).
  explicit SocketCanBus(const SocketCanConfig& cfg);
  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  // True when this kernel can open AF_CAN raw sockets; else false and *reason says why.
  static bool available(std::string* reason);

  [[nodiscard]] SendResult send(const CanFrame& f) noexcept override;
  // One sendmmsg() for up to 16 frames at a time; stops at the first frame not accepted.
  std::size_t send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept override;
  [[nodiscard]] RecvResult try_receive(RxFrame& out) noexcept override;
  [[nodiscard]] int fd() const noexcept override { return fd_; }
  [[nodiscard]] BusState state() const noexcept override { return state_; }
  void restart() noexcept override;
  [[nodiscard]] const CanBusCounters& counters() const noexcept override { return counters_; }
  [[nodiscard]] int errno_value() const noexcept override { return errno_; }

 private:
  std::string ifname_;
  int ifindex_ = 0;
  int fd_ = -1;
  bool fd_enabled_ = false;
  BusState state_ = BusState::error_active;
  CanBusCounters counters_;
  int errno_ = 0;
};

}  // namespace crease::drivers
