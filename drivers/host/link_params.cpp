#include "drivers/host/link_params.h"

#include "drivers/can/mock_can_bus.h"
#include "drivers/can/socket_can_bus.h"
#include "drivers/host/bus_prefix.h"

namespace crease::drivers {

std::unique_ptr<CanBus> open_bus_from_params(const Params& p) {
  const std::string kind = p.get<std::string>("bus_kind", "mock");
  std::string bus = p.get<std::string>("bus");
  if (kind == "mock") {
    const auto prefix = bus_prefix_from_params(p, std::nullopt);
    if (prefix) bus = prefixed_bus(*prefix, bus);
    const auto host_node = static_cast<std::uint32_t>(p.get_in_range<int>("host_node", 100, 0, 100000));
    try {
      return std::make_unique<MockCanBus>(MockCanBusConfig{bus, host_node, 1'000'000, 5'000'000});
    } catch (const std::exception& e) {
      p.fail("bus", std::string(e.what()) +
                        (prefix ? " (is a sim_world or sim_devices instance with the same bus_prefix listed before "
                                  "this one?)"
                                : ""));
    }
  }
  if (kind == "socketcan") {
    if (p.has("bus_prefix")) p.fail("bus_prefix", "only for bus_kind: mock (a SocketCAN interface is named by bus)");
    try {
      return std::make_unique<SocketCanBus>(SocketCanConfig{bus, true, {}, false});
    } catch (const std::exception& e) {
      p.fail("bus", e.what());
    }
  }
  p.fail("bus_kind", "must be 'mock' or 'socketcan', got '" + kind + "'");
}

LinkMonitorConfig monitor_from_params(const Params& p) {
  LinkMonitorConfig m;
  m.timeout_cycles = p.get_in_range<int>("timeout_cycles", 2, 1, 100);
  m.crc_threshold = p.get_in_range<int>("crc_threshold", 10, 0, 1000);
  m.device_fault_cycles = p.get_in_range<int>("device_fault_cycles", 50, 1, 1'000'000);
  m.bus_off_grace_cycles = p.get_in_range<int>("bus_off_grace_cycles", 3, 0, 100);
  return m;
}

}  // namespace crease::drivers
