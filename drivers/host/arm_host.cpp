#include "drivers/host/arm_host.h"

namespace crease::drivers {

ArmHost::ArmHost(CanBus& bus, const ArmHostConfig& cfg) noexcept
    : CanDeviceHost(bus, cfg.node, cfg.monitor, cfg.heartbeat_period_cycles, cfg.nmt_retry_cycles,
                    cfg.restart_period_cycles),
      cfg_(cfg) {}

LinkHealth ArmHost::health() const noexcept {
  const LinkHealth h = monitor_.health();
  if (h == LinkHealth::fault) return h;
  if (reading_.drive == cia402::State::fault || reading_.drive == cia402::State::fault_reaction_active) {
    return LinkHealth::fault;
  }
  if (reading_.drive != cia402::State::operation_enabled) return LinkHealth::degraded;
  return h;
}

void ArmHost::read_from_rt(std::int64_t now_ns) noexcept {
  (void)now_ns;
  reading_.fresh = false;
  read_bus([this](const RxFrame& rx) {
    arm::Status st;
    return take(rx.frame, st, [&](const arm::Status& s) {
      if (!accept_status(s)) return;
      reading_.status = s;
      reading_.drive = cia402::state_from_statusword(s.statusword);
      reading_.status_rx_ns = rx.timestamp_ns;
      reading_.fresh = true;
    });
  });
  // A drive back in a non-fault state clears a latched joint-fault emergency.
  if (monitor_.emergency_active() && reading_.fresh && reading_.drive != cia402::State::fault &&
      reading_.drive != cia402::State::fault_reaction_active) {
    monitor_.on_emergency(false);
  }
}

void ArmHost::write_from_rt(const arm::Command& desired, std::int64_t now_ns) noexcept {
  (void)now_ns;
  if (!begin_write()) return;
  arm::Command c = desired;
  c.seq = next_seq();
  const bool link_fault = monitor_.health() == LinkHealth::fault && !monitor_.emergency_active();
  using S = cia402::State;
  const S drive = reading_.drive;
  safe_sent_ = false;
  if (link_fault) {
    controlword_ = cia402::kCmdQuickStop;  // the drive decelerates and holds
    safe_sent_ = true;
  } else {
    switch (drive) {
      case S::fault:
      case S::fault_reaction_active:
        // Rising edge of bit 7: alternate 0x00 / 0x80.
        controlword_ = (controlword_ & cia402::kCwFaultReset) ? cia402::kCmdDisableVoltage : cia402::kCmdFaultReset;
        safe_sent_ = true;
        break;
      case S::not_ready_to_switch_on:
      case S::switch_on_disabled: controlword_ = cia402::kCmdShutdown; break;
      case S::ready_to_switch_on: controlword_ = cia402::kCmdSwitchOn; break;
      case S::switched_on:
      case S::operation_enabled: controlword_ = cia402::kCmdEnableOperation; break;
      case S::quick_stop_active: controlword_ = cia402::kCmdDisableVoltage; break;
    }
  }
  c.controlword = controlword_;
  if (drive != S::operation_enabled || safe_sent_) {
    for (int j = 0; j < arm::kJoints; ++j) {
      c.position_rad[j] = reading_.status.position_rad[j];
      c.velocity_rad_s[j] = 0.0f;
    }
  }
  add(arm::encode(cfg_.node, c));
  end_write(c.seq);
}

}  // namespace crease::drivers
