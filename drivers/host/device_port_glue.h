// The glue between a CAN device host (HandHost, ArmHost) and the ports of its driver plugin,
// shared by plugins/hand_driver and plugins/arm_driver. Header-only; everything called from
// update() is RT-safe (no allocation, no locks, no blocking).
#pragma once

#include <cstdint>
#include <memory>

#include "core/params.h"
#include "core/plugin.h"
#include "core/port_types/hand.h"
#include "drivers/can/can_bus.h"
#include "drivers/host/link_monitor.h"
#include "drivers/host/link_params.h"

namespace crease::drivers {

[[nodiscard]] inline DeviceHealth to_device_health(LinkHealth h) noexcept {
  switch (h) {
    case LinkHealth::ok: return DeviceHealth::ok;
    case LinkHealth::degraded: return DeviceHealth::degraded;
    case LinkHealth::fault: return DeviceHealth::fault;
  }
  return DeviceHealth::fault;
}

// A plugin stays scheduled through link faults (it recovers by itself); what it returns to the
// host, once per cycle. A `fault` health that lasted device_fault_cycles consecutive cycles
// after start-up (LinkMonitor::past_start_up) is Status::device_fault: the host counts a device
// fault and shows it as the instance's health until the link is ok or degraded again. A
// shorter fault (the safe state is commanded all the same), a degraded link and a link before
// first contact are Status::degraded; ok is ok. Never Status::fault. RT-safe.
class DeviceFaultReport {
 public:
  explicit DeviceFaultReport(int device_fault_cycles = 50) noexcept : cycles_(device_fault_cycles) {}
  // The read phase's verdict, after the host read the bus.
  Status update(LinkHealth h, const LinkMonitor& monitor) noexcept { return update(h, monitor.past_start_up()); }
  // The same for a link without a LinkMonitor (the tactile link): PAST_START_UP says whether it
  // has answered once or had its first-contact cycles to do so.
  Status update(LinkHealth h, bool past_start_up) noexcept {
    fault_run_ = h != LinkHealth::fault ? 0 : fault_run_ < cycles_ ? fault_run_ + 1 : cycles_;  // saturates
    if (h == LinkHealth::ok) status_ = Status::ok;
    else if (fault_run_ >= cycles_ && past_start_up) status_ = Status::device_fault;
    else status_ = Status::degraded;
    return status_;
  }
  // This cycle's verdict again (the write phase).
  [[nodiscard]] Status status() const noexcept { return status_; }

 private:
  int cycles_;
  int fault_run_ = 0;  // consecutive cycles in fault, at most cycles_
  Status status_ = Status::degraded;
};

// Configure time: the node (`node`, 1..126), the link monitor and the bus the parameters name
// (link_params.h) into a HandHostConfig / ArmHostConfig. Throws ConfigError on a bad value.
template <typename HostConfig>
[[nodiscard]] std::unique_ptr<CanBus> configure_can_device(const Params& p, HostConfig& cfg, int default_node) {
  cfg.node = static_cast<std::uint8_t>(p.get_in_range<int>("node", default_node, 1, 126));
  cfg.monitor = monitor_from_params(p);
  return open_bus_from_params(p);
}

// The link fields every device state port carries (HandState, ArmState) from the host's
// latest reading: reception and device time, valid bits (0 unless fresh), health, acks.
template <typename State, typename Host>
void fill_link_state(State& s, const Host& host) noexcept {
  const auto& r = host.reading();
  const LinkCounters& c = host.monitor().counters();
  s.timestamp_ns = r.status_rx_ns;
  s.device_time_us = r.status.device_time_us;
  s.valid = r.fresh ? r.status.valid : 0;
  s.fresh = r.fresh ? 1 : 0;
  s.health = to_device_health(host.health());
  s.acked_seq = host.monitor().last_acked_seq();
  s.commands_sent = c.commands_sent;
  s.commands_failed = c.commands_failed;
}

// The newest command of a latest-value input, held across cycles (commands are never queued):
// nullptr until a first command has arrived (the driver then holds). RT-safe.
template <typename Command>
[[nodiscard]] const Command* held_command(LatestInput<Command>& in) noexcept {
  return in.poll().has_data() ? &in.value() : nullptr;
}

}  // namespace crease::drivers
