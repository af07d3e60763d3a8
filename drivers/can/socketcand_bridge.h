// SocketcandBridge: a socketcand server on 127.0.0.1 for one CAN bus (rawmode, classic frames),
// so python-can ("socketcand" interface) and other socketcand clients can watch and inject
// frames. Runs its own (non-RT) thread and is the only user of `bus` while it runs. A client's
// frames go onto the bus and to every other client in rawmode (as socketcand's per-client
// raw sockets see each other's frames); the sender does not get its own back.
// FD and error frames are not forwarded (socketcand rawmode is classic only); they are counted.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "drivers/can/can_bus.h"

namespace crease::drivers {

struct SocketcandBridgeStats {
  std::uint64_t to_clients = 0, from_clients = 0, skipped_fd = 0, bad_messages = 0, tx_no_buffers = 0;
};

class SocketcandBridge {
 public:
  // Listens on 127.0.0.1:port (0: any free port, see port()). `interface` is the name clients
  // must open. Throws std::runtime_error naming the port on failure.
  SocketcandBridge(CanBus& bus, std::uint16_t port, std::string interface = "can0");
  ~SocketcandBridge();
  SocketcandBridge(const SocketcandBridge&) = delete;
  SocketcandBridge& operator=(const SocketcandBridge&) = delete;
  [[nodiscard]] std::uint16_t port() const noexcept { return port_; }
  [[nodiscard]] SocketcandBridgeStats stats() const noexcept;

 private:
  void run();
  CanBus& bus_;
  std::string interface_;
  int listen_fd_ = -1, wake_fd_ = -1;
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> to_clients_{0}, from_clients_{0}, skipped_fd_{0}, bad_{0}, nobufs_{0};
  std::thread thread_;
};

}  // namespace crease::drivers
