#include "drivers/simdevice/sim_hand.h"

#include <cmath>

namespace crease::drivers::sim {

SimHand::SimHand(CanBus& bus, const SimHandConfig& cfg) noexcept : bus_(bus), cfg_(cfg) {
  for (float& k : stiffness_) k = 5.0f;  // N m/rad until the host sends its own
}

void SimHand::send(const CanFrame& f) noexcept {
  if (silent_.load(std::memory_order_relaxed)) return;
  if (bus_.send(f) != SendResult::ok) ++counters_.send_failures;
}

void SimHand::on_frame(const CanFrame& f, std::int64_t now_ns) noexcept {
  canopen::NmtCommand nc;
  std::uint8_t node;
  if (canopen::decode_nmt(f, nc, node)) {
    if (node != 0 && node != cfg_.node) return;
    switch (nc) {
      case canopen::NmtCommand::start: nmt_ = canopen::NmtState::operational; break;
      case canopen::NmtCommand::stop: nmt_ = canopen::NmtState::stopped; break;
      case canopen::NmtCommand::pre_operational: nmt_ = canopen::NmtState::pre_operational; break;
      case canopen::NmtCommand::reset_node: booted_ = false; nmt_ = canopen::NmtState::boot_up; break;
    }
    send(canopen::encode_heartbeat(cfg_.node, nmt_));
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
  hand::Command c;
  switch (hand::decode(cfg_.node, f, c)) {
    case Decode::ok:
      if (nmt_ != canopen::NmtState::operational) return;
      ++counters_.commands;
      integrate(now_ns);
      cmd_seq_ = c.seq;
      last_cmd_ns_ = now_ns;
      enabled_ = (c.flags & hand::kCmdEnable) != 0;
      for (int j = 0; j < hand::kJoints; ++j) target_[j] = c.target_rad[j];
      if (safe_ && enabled_) {
        safe_ = false;
        canopen::Emcy e{cfg_.node, canopen::kEmcyReset, 0, 0, static_cast<std::uint32_t>((now_ns - t0_ns_) / 1000)};
        send(canopen::encode_emcy(e));
        ++counters_.emcy_sent;
      }
      return;
    case Decode::bad_crc: ++counters_.bad_crc; return;
    default: break;
  }
  hand::Stiffness s;
  if (hand::decode(cfg_.node, f, s) == Decode::ok) {
    stiff_seq_ = s.seq;
    for (int j = 0; j < hand::kJoints; ++j) stiffness_[j] = s.stiffness_nm_per_rad[j];
  }
}

void SimHand::integrate(std::int64_t now_ns) noexcept {
  const double dt = static_cast<double>(now_ns - last_step_ns_) * 1e-9;
  last_step_ns_ = now_ns;
  if (dt <= 0 || safe_ || !enabled_) return;  // safe state: hold position, zero force
  const double a = 1.0 - std::exp(-dt / cfg_.tau_s);
  for (int j = 0; j < hand::kJoints; ++j) {
    const float k = stiffness_[j];
    const float deflect = k > 1e-3f ? ext_torque_[j].load(std::memory_order_relaxed) / k : 0.0f;
    pos_[j] += static_cast<float>(a * ((target_[j] - deflect) - pos_[j]));
  }
}

void SimHand::send_status() noexcept {
  hand::Status s;
  s.cmd_seq = cmd_seq_;
  s.stiff_seq = stiff_seq_;
  s.nmt = nmt_;
  s.flags = static_cast<std::uint8_t>((enabled_ && !safe_ ? hand::kStatusEnabled : 0) |
                                      (safe_ ? hand::kStatusWatchdogHold : 0));
  s.sync_counter = sync_counter_;
  s.device_time_us = static_cast<std::uint32_t>((last_step_ns_ - t0_ns_) / 1000);
  s.valid = 0xFFFFF;
  for (int j = 0; j < hand::kJoints; ++j) s.position_rad[j] = pos_[j];
  send(hand::encode(cfg_.node, s));
  if (cfg_.pressure_sensors) {
    hand::Pressure p;
    p.cmd_seq = cmd_seq_;
    p.sync_counter = sync_counter_;
    p.valid = 0x1F;
    p.device_time_us = s.device_time_us;
    for (int k = 0; k < hand::kPressureSensors; ++k) p.pressure_kpa[k] = pressure_[k].load(std::memory_order_relaxed);
    send(hand::encode(cfg_.node, p));
  }
  ++counters_.statuses_sent;
}

void SimHand::step(std::int64_t now_ns) noexcept {
  if (!booted_) {
    booted_ = true;
    t0_ns_ = last_step_ns_ = last_cmd_ns_ = now_ns;
    nmt_ = canopen::NmtState::boot_up;
    send(canopen::encode_heartbeat(cfg_.node, nmt_));
    nmt_ = cfg_.auto_start ? canopen::NmtState::operational : canopen::NmtState::pre_operational;
    last_heartbeat_ns_ = now_ns;
  }
  RxFrame rx;
  for (int i = 0; i < 64; ++i) {
    const RecvResult r = bus_.try_receive(rx);
    if (r == RecvResult::empty || r == RecvResult::error) break;
    if (r == RecvResult::frame) on_frame(rx.frame, now_ns);
  }
  if (bus_.state() == BusState::bus_off) bus_.restart();  // auto restart, like restart-ms
  if (!safe_ && now_ns - last_cmd_ns_ > cfg_.watchdog_ns) {
    integrate(now_ns);
    safe_ = true;  // hold where we are, zero force
    ++counters_.watchdog_trips;
    canopen::Emcy e{cfg_.node, canopen::kEmcyHostTimeout, 0x01, 0, static_cast<std::uint32_t>((now_ns - t0_ns_) / 1000)};
    send(canopen::encode_emcy(e));
    ++counters_.emcy_sent;
  }
  integrate(now_ns);
  if (now_ns - last_heartbeat_ns_ >= cfg_.heartbeat_period_ns) {
    last_heartbeat_ns_ = now_ns;
    send(canopen::encode_heartbeat(cfg_.node, nmt_));
  }
  safe_pub_.store(safe_);
  nmt_pub_.store(nmt_);
  for (int j = 0; j < hand::kJoints; ++j) pos_pub_[j].store(pos_[j], std::memory_order_relaxed);
}

}  // namespace crease::drivers::sim
