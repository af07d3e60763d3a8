// ArmHost: the controller side of one 7-joint arm drive (drivers/README.md §4). It walks the
// CiA 402 state machine to operation enabled by itself (shutdown, switch on, enable; fault
// reset on a rising edge when the drive reports fault), sends the latest set points only in
// operation enabled (the measured position otherwise, so enabling never jumps), and commands
// quick stop while the link is in fault. RT-safe like HandHost.
#pragma once

#include "drivers/can/can_bus.h"
#include "drivers/host/can_device_host.h"
#include "drivers/protocol/arm_protocol.h"
#include "drivers/protocol/cia402.h"

namespace crease::drivers {

struct ArmHostConfig {
  std::uint8_t node = 10;
  LinkMonitorConfig monitor;
  int heartbeat_period_cycles = 100;
  int nmt_retry_cycles = 50;
  int restart_period_cycles = 100;
};

struct ArmReading {
  arm::Status status;
  cia402::State drive = cia402::State::not_ready_to_switch_on;
  std::int64_t status_rx_ns = 0;
  bool fresh = false;
};

class ArmHost : public CanDeviceHost {
 public:
  ArmHost(CanBus& bus, const ArmHostConfig& cfg) noexcept;
  void read_from_rt(std::int64_t now_ns) noexcept;
  // desired: set points and mode (seq and controlword are the host's).
  void write_from_rt(const arm::Command& desired, std::int64_t now_ns) noexcept;
  [[nodiscard]] const ArmReading& reading() const noexcept { return reading_; }
  // fault also while the drive is not operation enabled after having been enabled.
  [[nodiscard]] LinkHealth health() const noexcept;
  [[nodiscard]] std::uint16_t last_controlword() const noexcept { return controlword_; }

 private:
  ArmHostConfig cfg_;
  ArmReading reading_;
  std::uint16_t controlword_ = 0;
};

}  // namespace crease::drivers
