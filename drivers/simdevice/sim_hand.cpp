#include "drivers/simdevice/sim_hand.h"

#include <cmath>

namespace crease::drivers::sim {

SimHand::SimHand(CanBus& bus, const SimHandConfig& cfg) noexcept
    : CanopenDevice(bus, cfg.node, cfg.watchdog_ns, cfg.heartbeat_period_ns, cfg.auto_start), cfg_(cfg) {
  for (float& k : stiffness_) k = 5.0f;  // N m/rad until the host sends its own
}

void SimHand::on_pdo(const CanFrame& f, std::int64_t now_ns) noexcept {
  hand::Command c;
  const Decode d = hand::decode(cfg_.node, f, c);
  if (accept_command(d, c.seq, now_ns)) {
    enabled_ = (c.flags & hand::kCmdEnable) != 0;
    for (int j = 0; j < hand::kJoints; ++j) target_[j] = c.target_rad[j];
    if (safe_ && enabled_) {
      safe_ = false;
      emcy(canopen::kEmcyReset, now_ns);
    }
    return;
  }
  if (d == Decode::ok || d == Decode::bad_crc) return;
  hand::Stiffness s;
  if (hand::decode(cfg_.node, f, s) == Decode::ok) {
    stiff_seq_ = s.seq;
    for (int j = 0; j < hand::kJoints; ++j) stiffness_[j] = s.stiffness_nm_per_rad[j];
  }
}

void SimHand::set_joint_positions(const float (&rad)[hand::kJoints]) noexcept {
  for (int j = 0; j < hand::kJoints; ++j) pos_[j] = rad[j];
}

void SimHand::integrate(std::int64_t now_ns) noexcept {
  const double dt = static_cast<double>(now_ns - last_step_ns_) * 1e-9;
  last_step_ns_ = now_ns;
  if (cfg_.external_positions) return;        // the world moves the joints
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
  s.device_time_us = device_time_us();
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

void SimHand::supervise(std::int64_t now_ns) noexcept {
  if (!safe_ && command_timed_out(now_ns)) {
    integrate(now_ns);
    safe_ = true;  // hold where we are, zero force
    ++counters_.watchdog_trips;
    emcy(canopen::kEmcyHostTimeout, now_ns);
  }
  integrate(now_ns);
}

void SimHand::publish() noexcept {
  safe_pub_.store(safe_);
  nmt_pub_.store(nmt_);
  for (int j = 0; j < hand::kJoints; ++j) pos_pub_[j].store(pos_[j], std::memory_order_relaxed);
}

}  // namespace crease::drivers::sim
