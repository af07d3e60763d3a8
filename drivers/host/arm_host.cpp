#include "drivers/host/arm_host.h"

namespace crease::drivers {

ArmHost::ArmHost(CanBus& bus, const ArmHostConfig& cfg) noexcept : bus_(bus), cfg_(cfg), monitor_(cfg.monitor) {}

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
  monitor_.begin_read();
  reading_.fresh = false;
  RxFrame rx;
  for (int i = 0; i < 256; ++i) {
    const RecvResult r = bus_.try_receive(rx);
    if (r == RecvResult::empty || r == RecvResult::error) break;
    if (r != RecvResult::frame) continue;
    arm::Status st;
    const Decode d = arm::decode(cfg_.node, rx.frame, st);
    if (d == Decode::ok) {
      operational_ = st.nmt == canopen::NmtState::operational;
      if (monitor_.on_status(st.cmd_seq, st.sync_counter, st.device_time_us)) {
        reading_.status = st;
        reading_.drive = cia402::state_from_statusword(st.statusword);
        reading_.status_rx_ns = rx.timestamp_ns;
        reading_.fresh = true;
      }
      continue;
    }
    if (d == Decode::bad_crc) {
      monitor_.on_bad_crc();
      continue;
    }
    canopen::Emcy e;
    if (canopen::decode_emcy(rx.frame, e) && e.node == cfg_.node) {
      // Host timeout: the drive quick-stopped itself; the state machine below re-enables it.
      monitor_.on_emergency(e.code != canopen::kEmcyReset && e.code != canopen::kEmcyHostTimeout);
      continue;
    }
    std::uint8_t node;
    canopen::NmtState s;
    if (canopen::decode_heartbeat(rx.frame, node, s) && node == cfg_.node) {
      operational_ = s == canopen::NmtState::operational;
    }
  }
  monitor_.end_read(bus_.state() == BusState::bus_off);
  // A drive back in a non-fault state clears a latched joint-fault emergency.
  if (monitor_.emergency_active() && reading_.fresh && reading_.drive != cia402::State::fault &&
      reading_.drive != cia402::State::fault_reaction_active) {
    monitor_.on_emergency(false);
  }
}

void ArmHost::write_from_rt(const arm::Command& desired, std::int64_t now_ns) noexcept {
  (void)now_ns;
  ++cycle_;
  if (bus_.state() == BusState::bus_off) {
    if (cycle_ % static_cast<std::uint64_t>(cfg_.restart_period_cycles) == 1) bus_.restart();
    safe_sent_ = true;
    return;
  }
  CanFrame out[4];  // sent as one batch
  std::size_t n = 0;
  if (!operational_ && cycle_ % static_cast<std::uint64_t>(cfg_.nmt_retry_cycles) == 1) {
    out[n++] = canopen::encode_nmt(canopen::NmtCommand::start, cfg_.node);
  }
  arm::Command c = desired;
  c.seq = ++seq_;
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
  out[n++] = arm::encode(cfg_.node, c);
  sync_ = canopen::next_sync_counter(sync_);
  out[n++] = canopen::encode_sync(sync_);
  monitor_.on_sent(c.seq, sync_);
  if (cycle_ % static_cast<std::uint64_t>(cfg_.heartbeat_period_cycles) == 1) {
    out[n++] = canopen::encode_heartbeat(canopen::kHostNode, canopen::NmtState::operational);
  }
  SendResult last;
  send_failures_ += n - bus_.send_batch({out, n}, &last);
}

}  // namespace crease::drivers
