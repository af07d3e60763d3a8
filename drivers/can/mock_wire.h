// The record a MockCanBus node and its MockCanBroker exchange over an AF_UNIX SOCK_SEQPACKET
// connection: one record per message, boundaries kept. Internal to the mock bus.
#pragma once

#include <sys/socket.h>
#include <sys/un.h>

#include <cstdint>
#include <string>

#include "drivers/can/can_frame.h"

namespace crease::drivers::mockwire {

enum Kind : std::uint32_t {
  kData = 0,     // a CAN frame (or an error frame, CAN_ERR_FLAG) on the bus
  kHello = 1,    // node -> broker: first record; frame.can_id = node id
  kRestart = 2,  // node -> broker: leave bus-off
};

struct Record {
  std::uint32_t kind = kData;
  std::uint32_t node = 0;          // sender's node id (broker -> node: the original sender)
  std::int64_t timestamp_ns = 0;   // broker -> node: end of the frame on the virtual bus
  CanFrame frame;
};
static_assert(sizeof(Record) == 88);

// Abstract-namespace AF_UNIX address for a bus name ("\0crease-can/<name>"). Throws if the
// name is empty or too long.
socklen_t make_address(const std::string& bus_name, sockaddr_un& out);

}  // namespace crease::drivers::mockwire
