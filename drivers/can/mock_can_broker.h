// MockCanBroker: the medium of a user-space CAN bus. Nodes (MockCanBus, in this process or
// another) connect to it by bus name over AF_UNIX SOCK_SEQPACKET (only processes of the same
// user, root or the configured group: others are refused, counted and logged to stderr); the broker forwards every
// frame to every other node, timestamps it with a bit-timed bus-load model (a virtual bus
// clock at the configured bitrates) and injects seeded faults. Frames travel through
// shared-memory rings (mock_wire.h); one (non-RT) thread per process serves every broker of
// that process (mock_reactor.h).
#pragma once

#include <cstdint>
#include <string>

#include "drivers/can/can_bus.h"

namespace crease::drivers {

// Per-frame fault probabilities (0..1), drawn from one seeded generator in frame order.
struct CanFaultConfig {
  std::uint64_t seed = 1;
  double drop = 0;          // frame vanishes
  double corrupt = 0;       // one payload bit flipped (the application CRC must catch it)
  double duplicate = 0;     // delivered twice
  double reorder = 0;       // held back and delivered after the next frame
  double delay = 0;         // delivered delay_ns late
  std::int64_t delay_ns = 2'000'000;
  double error_frame = 0;   // a protocol error frame is broadcast before the frame
};

struct MockCanBrokerConfig {
  std::string name;                       // bus name (abstract AF_UNIX socket)
  std::uint32_t nominal_bps = 1'000'000;  // arbitration bitrate; 0 = no bus-time model
  std::uint32_t data_bps = 5'000'000;     // FD data-phase bitrate
  bool pace = false;  // deliver frames only when the virtual bus has finished sending them
  // Besides this process's user (and root), members of this group may join (mock_access.h);
  // empty: the environment variable CREASE_CAN_GROUP, or nobody else.
  std::string group;
};

struct MockCanBrokerStats {
  std::uint64_t forwarded = 0;     // frame deliveries to nodes
  std::uint64_t received = 0;      // frames received from nodes
  std::uint64_t dropped_fault = 0; // by drop fault, silent node or bus-off sender
  std::uint64_t rx_overflow = 0;   // a node's receive queue was full
  std::int64_t busy_ns = 0;        // virtual bus time used
  std::uint64_t refused = 0;       // connections refused: another user, not in the bus's group
  int nodes = 0;
};

class MockCanBroker {
 public:
  // Binds the bus name and joins the process's broker thread. Throws std::runtime_error naming the bus
  // if the name is taken or a socket call fails, std::invalid_argument for an unknown group.
  explicit MockCanBroker(MockCanBrokerConfig cfg);
  ~MockCanBroker();
  MockCanBroker(const MockCanBroker&) = delete;
  MockCanBroker& operator=(const MockCanBroker&) = delete;

  void set_faults(const CanFaultConfig& f);
  // Frames sent by this node id are silently discarded (the device "falls silent").
  void set_silent(std::uint32_t node_id, bool silent);
  // Puts a node into bus-off (it receives CAN_ERR_BUSOFF; its frames are discarded until it
  // calls restart()).
  void force_bus_off(std::uint32_t node_id);
  // Broadcasts one error frame to every node.
  void inject_error_frame(const CanFrame& err);
  [[nodiscard]] MockCanBrokerStats stats() const;
  [[nodiscard]] int connected_nodes() const;
  [[nodiscard]] const std::string& name() const noexcept { return cfg_.name; }

 private:
  struct Impl;
  MockCanBrokerConfig cfg_;
  Impl* impl_;
};

// Runs a broker in the calling thread until SIGINT/SIGTERM (for `crease-simdevice broker`).
int run_broker_until_signal(const MockCanBrokerConfig& cfg, const CanFaultConfig& faults);

}  // namespace crease::drivers
