// Helpers shared by the mock CAN bus tests.
#pragma once

#include <poll.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"

namespace crease::drivers::testing {

inline std::string unique_bus(const char* tag) {
  static int n = 0;
  return std::string(tag) + "-" + std::to_string(::getpid()) + "-" + std::to_string(++n);
}

// Waits up to timeout_ms for one data frame (error frames are returned too).
inline RecvResult recv_wait(CanBus& bus, RxFrame& out, int timeout_ms = 1000) {
  for (;;) {
    const RecvResult r = bus.try_receive(out);
    if (r != RecvResult::empty) return r;
    pollfd p{bus.fd(), POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) return RecvResult::empty;
  }
}

inline std::vector<std::uint32_t> drain_ids(CanBus& bus, int quiet_ms = 50) {
  std::vector<std::uint32_t> ids;
  RxFrame rx;
  while (recv_wait(bus, rx, quiet_ms) == RecvResult::frame) ids.push_back(rx.frame.id());
  return ids;
}

inline CanFrame frame_with_id(std::uint32_t id) {
  const std::uint8_t b[4] = {static_cast<std::uint8_t>(id), 0xA5, 0x5A, 0x01};
  return CanFrame::fd(id, b);
}

inline MockCanBusConfig node(const std::string& bus, std::uint32_t id, std::uint32_t bps = 0) {
  return {bus, id, bps, bps ? 5'000'000u : 0u};
}

// Waits until the broker counts n nodes; false after ~0.4 s.
inline bool wait_nodes(const MockCanBroker& b, int n) {
  for (int i = 0; i < 200 && b.connected_nodes() < n; ++i) ::usleep(2000);
  return b.connected_nodes() == n;
}

}  // namespace crease::drivers::testing
