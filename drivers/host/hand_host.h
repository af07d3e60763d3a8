// HandHost: the controller side of one hand on its own CAN FD bus (drivers/README.md §3).
// Each cycle: read_from_rt() drains the bus (status, pressure, EMCY, heartbeats), then
// write_from_rt() sends the command (or the safe command when the link is in fault), the
// stiffness when it changed or every 100 cycles, the SYNC and, every 100 ms, the host heartbeat.
// The latest set point is always the one sent: after a fault the device gets the newest
// command, never a backlog. All calls are RT-safe for a MockCanBus (SocketCanBus::restart
// uses netlink and is called at most once per restart_period_cycles).
#pragma once

#include "drivers/can/can_bus.h"
#include "drivers/host/can_device_host.h"
#include "drivers/protocol/hand_protocol.h"

namespace crease::drivers {

struct HandHostConfig {
  std::uint8_t node = 1;
  bool pressure_sensors = false;
  LinkMonitorConfig monitor;
  int heartbeat_period_cycles = 100;
  int nmt_retry_cycles = 50;          // resend NMT start while the device is not operational
  int restart_period_cycles = 100;    // bus-off: try a restart this often
};

struct HandReading {
  hand::Status status;              // latest decoded status
  hand::Pressure pressure;          // latest pressure (if the hand has the sensors)
  std::int64_t status_rx_ns = 0;    // reception time of `status`
  bool fresh = false;               // `status` answers this cycle's SYNC
  bool pressure_fresh = false;
};

class HandHost : public CanDeviceHost {
 public:
  HandHost(CanBus& bus, const HandHostConfig& cfg) noexcept;
  void read_from_rt(std::int64_t now_ns) noexcept;
  // desired: the controller's command (its seq is ignored; the host numbers commands).
  void write_from_rt(const hand::Command& desired, const hand::Stiffness& stiffness, std::int64_t now_ns) noexcept;
  [[nodiscard]] const HandReading& reading() const noexcept { return reading_; }
  [[nodiscard]] LinkHealth health() const noexcept { return monitor_.health(); }
  // commanding_safe_state(): the last write sent enable = 0 (hold, zero force).

 private:
  HandHostConfig cfg_;
  HandReading reading_;
  std::uint16_t stiff_seq_ = 0;
  std::uint64_t last_stiff_cycle_ = 0;
  float last_stiffness_[hand::kJoints] = {};
  bool stiffness_sent_ = false;
};

}  // namespace crease::drivers
