#include "drivers/simdevice/canopen_device.h"

namespace crease::drivers::sim {

void CanopenDevice::send(const CanFrame& f) noexcept {
  if (silent_.load(std::memory_order_relaxed)) return;
  if (bus_.send(f) != SendResult::ok) ++counters_.send_failures;
}

void CanopenDevice::emcy(std::uint16_t code, std::int64_t now_ns) noexcept {
  const canopen::Emcy e{node_, code, static_cast<std::uint8_t>(code ? 0x01 : 0), 0,
                        static_cast<std::uint32_t>((now_ns - t0_ns_) / 1000)};
  send(canopen::encode_emcy(e));
  ++counters_.emcy_sent;
}

bool CanopenDevice::accept_command(Decode d, std::uint16_t seq, std::int64_t now_ns) noexcept {
  if (d == Decode::bad_crc) ++counters_.bad_crc;
  if (d != Decode::ok || nmt_ != canopen::NmtState::operational) return false;
  ++counters_.commands;
  integrate(now_ns);
  cmd_seq_ = seq;
  last_cmd_ns_ = now_ns;
  return true;
}

void CanopenDevice::on_frame(const CanFrame& f, std::int64_t now_ns) noexcept {
  canopen::NmtCommand nc;
  std::uint8_t node;
  if (canopen::decode_nmt(f, nc, node)) {
    if (node != 0 && node != node_) return;
    switch (nc) {
      case canopen::NmtCommand::start: nmt_ = canopen::NmtState::operational; break;
      case canopen::NmtCommand::stop: nmt_ = canopen::NmtState::stopped; break;
      case canopen::NmtCommand::pre_operational: nmt_ = canopen::NmtState::pre_operational; break;
      case canopen::NmtCommand::reset_node: booted_ = false; nmt_ = canopen::NmtState::boot_up; break;
    }
    send(canopen::encode_heartbeat(node_, nmt_));
    return;
  }
  std::uint8_t counter;
  if (canopen::decode_sync(f, counter)) {
    ++counters_.syncs;
    sync_counter_ = counter;
    if (nmt_ == canopen::NmtState::operational) {
      integrate(now_ns);
      send_status();
    }
    return;
  }
  on_pdo(f, now_ns);
}

void CanopenDevice::step(std::int64_t now_ns) noexcept {
  if (!booted_) {
    booted_ = true;
    t0_ns_ = last_step_ns_ = last_cmd_ns_ = last_heartbeat_ns_ = now_ns;
    nmt_ = canopen::NmtState::boot_up;
    send(canopen::encode_heartbeat(node_, nmt_));
    nmt_ = auto_start_ ? canopen::NmtState::operational : canopen::NmtState::pre_operational;
  }
  RxFrame rx;
  for (int i = 0; i < 64; ++i) {
    const RecvResult r = bus_.try_receive(rx);
    if (r == RecvResult::empty || r == RecvResult::error) break;
    if (r == RecvResult::frame) on_frame(rx.frame, now_ns);
  }
  if (bus_.state() == BusState::bus_off) bus_.restart();  // auto restart, like restart-ms
  supervise(now_ns);
  if (now_ns - last_heartbeat_ns_ >= heartbeat_period_ns_) {
    last_heartbeat_ns_ = now_ns;
    send(canopen::encode_heartbeat(node_, nmt_));
  }
  publish();
}

}  // namespace crease::drivers::sim
