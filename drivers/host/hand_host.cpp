#include "drivers/host/hand_host.h"

#include <cstring>

namespace crease::drivers {

HandHost::HandHost(CanBus& bus, const HandHostConfig& cfg) noexcept : bus_(bus), cfg_(cfg), monitor_(cfg.monitor) {}

void HandHost::read_from_rt(std::int64_t now_ns) noexcept {
  (void)now_ns;
  monitor_.begin_read();
  reading_.fresh = false;
  reading_.pressure_fresh = false;
  RxFrame rx;
  for (int i = 0; i < 256; ++i) {
    const RecvResult r = bus_.try_receive(rx);
    if (r == RecvResult::empty || r == RecvResult::error) break;
    if (r != RecvResult::frame) continue;
    hand::Status st;
    const Decode d = hand::decode(cfg_.node, rx.frame, st);
    if (d == Decode::ok) {
      operational_ = st.nmt == canopen::NmtState::operational;
      if (monitor_.on_status(st.cmd_seq, st.sync_counter, st.device_time_us)) {
        reading_.status = st;
        reading_.status_rx_ns = rx.timestamp_ns;
        reading_.fresh = true;
      }
      continue;
    }
    if (d == Decode::bad_crc) {
      monitor_.on_bad_crc();
      continue;
    }
    hand::Pressure p;
    const Decode dp = hand::decode(cfg_.node, rx.frame, p);
    if (dp == Decode::ok) {
      if (p.sync_counter == sync_) {
        reading_.pressure = p;
        reading_.pressure_fresh = true;
      }
      continue;
    }
    if (dp == Decode::bad_crc) {
      monitor_.on_bad_crc();
      continue;
    }
    canopen::Emcy e;
    if (canopen::decode_emcy(rx.frame, e) && e.node == cfg_.node) {
      // A host-timeout EMCY reports that the hand already holds itself safe (our commands
      // stopped reaching it); it clears when our commands arrive again, so it does not latch.
      if (e.code == canopen::kEmcyHostTimeout) {
        monitor_.on_emergency(false);
        ++host_timeout_emcys_;
      } else {
        monitor_.on_emergency(e.code != canopen::kEmcyReset);
      }
      continue;
    }
    std::uint8_t node;
    canopen::NmtState s;
    if (canopen::decode_heartbeat(rx.frame, node, s) && node == cfg_.node) {
      operational_ = s == canopen::NmtState::operational;
    }
  }
  monitor_.end_read(bus_.state() == BusState::bus_off);
}

void HandHost::write_from_rt(const hand::Command& desired, const hand::Stiffness& stiffness, std::int64_t now_ns) noexcept {
  (void)now_ns;
  ++cycle_;
  if (bus_.state() == BusState::bus_off) {
    if (cycle_ % static_cast<std::uint64_t>(cfg_.restart_period_cycles) == 1) bus_.restart();
    safe_sent_ = true;  // nothing can be sent; the device's watchdog holds it safe
    return;
  }
  // Everything this cycle sends goes out in one batch (one sendmmsg on SocketCAN, one ring
  // update on the mock bus).
  CanFrame out[5];
  std::size_t n = 0;
  if (!operational_ && cycle_ % static_cast<std::uint64_t>(cfg_.nmt_retry_cycles) == 1) {
    out[n++] = canopen::encode_nmt(canopen::NmtCommand::start, cfg_.node);
  }
  hand::Command c = desired;
  c.seq = ++seq_;
  safe_sent_ = monitor_.health() == LinkHealth::fault;
  if (safe_sent_) {
    c.flags = 0;  // hold position, zero force
    for (int j = 0; j < hand::kJoints; ++j) c.target_rad[j] = reading_.status.position_rad[j];
  }
  out[n++] = hand::encode(cfg_.node, c);
  const bool changed = !stiffness_sent_ ||
                       std::memcmp(last_stiffness_, stiffness.stiffness_nm_per_rad, sizeof(last_stiffness_)) != 0;
  if (changed || cycle_ - last_stiff_cycle_ >= 100) {
    hand::Stiffness s = stiffness;
    s.seq = ++stiff_seq_;
    out[n++] = hand::encode(cfg_.node, s);
    std::memcpy(last_stiffness_, stiffness.stiffness_nm_per_rad, sizeof(last_stiffness_));
    last_stiff_cycle_ = cycle_;
    stiffness_sent_ = true;
  }
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
