// The parameters every CAN driver plugin shares, read from its configuration (non-RT):
//   bus_kind   mock | socketcan (default mock)
//   bus        the mocked bus name or the SocketCAN interface (required)
//   bus_prefix mock only: the bus is `<bus_prefix>-<bus>`, "auto" the daemon's own prefix
//              (bus_prefix.h); absent: `bus` is the whole name
//   host_node  this controller's node id on a mocked bus (default 100)
//   timeout_cycles, crc_threshold, device_fault_cycles, bus_off_grace_cycles   the link monitor
//              (LinkMonitorConfig)
// Errors throw ConfigError naming the file, line and key (crease::Params).
#pragma once

#include <memory>

#include "core/params.h"
#include "drivers/can/can_bus.h"
#include "drivers/host/link_monitor.h"

namespace crease::drivers {

// Opens the bus the parameters name.
[[nodiscard]] std::unique_ptr<CanBus> open_bus_from_params(const Params& p);
[[nodiscard]] LinkMonitorConfig monitor_from_params(const Params& p);

}  // namespace crease::drivers
