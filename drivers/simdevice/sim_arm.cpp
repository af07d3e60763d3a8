#include "drivers/simdevice/sim_arm.h"

#include <cmath>

namespace crease::drivers::sim {

SimArm::SimArm(CanBus& bus, const SimArmConfig& cfg) noexcept
    : CanopenDevice(bus, cfg.node, cfg.watchdog_ns, cfg.heartbeat_period_ns, cfg.auto_start), cfg_(cfg) {
  drive_.power_up();
  for (int j = 0; j < arm::kJoints; ++j) pos_[j] = pos_sp_[j] = cfg.initial_position_rad[j];
  publish();
}

void SimArm::on_pdo(const CanFrame& f, std::int64_t now_ns) noexcept {
  arm::Command c;
  const Decode d = arm::decode(cfg_.node, f, c);
  if (!accept_command(d, c.seq, now_ns)) return;
  controlword_ = c.controlword;
  const cia402::State before = drive_.state();
  drive_.step(c.controlword, fault_.load(std::memory_order_relaxed));
  if (before != cia402::State::operation_enabled && drive_.operation_enabled()) {
    for (int j = 0; j < arm::kJoints; ++j) pos_sp_[j] = pos_[j];  // no jump on enable
  }
  if (watchdog_tripped_) {
    watchdog_tripped_ = false;
    emcy(canopen::kEmcyReset, now_ns);
  }
  mode_ = c.mode;
  if (drive_.operation_enabled()) {
    for (int j = 0; j < arm::kJoints; ++j) {
      pos_sp_[j] = c.position_rad[j];
      vel_sp_[j] = c.velocity_rad_s[j];
    }
  }
}

void SimArm::integrate(std::int64_t now_ns) noexcept {
  const double dt = static_cast<double>(now_ns - last_step_ns_) * 1e-9;
  last_step_ns_ = now_ns;
  if (dt <= 0) return;
  const double a = 1.0 - std::exp(-dt / cfg_.tau_s);
  for (int j = 0; j < arm::kJoints; ++j) {
    float vel_target = 0.0f;
    if (drive_.operation_enabled()) {
      if (mode_ == arm::kModeCyclicPosition) {
        const float before = pos_[j];
        pos_[j] += static_cast<float>(a * (pos_sp_[j] - pos_[j]));
        vel_[j] = static_cast<float>((pos_[j] - before) / dt);
        continue;
      }
      vel_target = vel_sp_[j];
    }
    // Velocity mode, quick stop and every other state: velocity lags to its target (0 = stop).
    vel_[j] += static_cast<float>(a * (vel_target - vel_[j]));
    pos_[j] += static_cast<float>(vel_[j] * dt);
  }
}

void SimArm::send_status() noexcept {
  arm::Status s;
  s.cmd_seq = cmd_seq_;
  s.statusword = cia402::statusword(drive_.state());
  s.device_time_us = device_time_us();
  s.valid = 0x7F;
  s.mode = mode_;
  s.error_code = error_code_;
  s.sync_counter = sync_counter_;
  s.nmt = nmt_;
  for (int j = 0; j < arm::kJoints; ++j) {
    s.position_rad[j] = pos_[j];
    s.velocity_rad_s[j] = vel_[j];
  }
  send(arm::encode(cfg_.node, s));
  ++counters_.statuses_sent;
}

void SimArm::supervise(std::int64_t now_ns) noexcept {
  const bool fault = fault_.load(std::memory_order_relaxed);
  if (fault && !fault_reported_) {
    fault_reported_ = true;
    error_code_ = canopen::kEmcyJointFault;
    drive_.raise_fault();
    emcy(canopen::kEmcyJointFault, now_ns);
  } else if (!fault && fault_reported_ && drive_.state() != cia402::State::fault &&
             drive_.state() != cia402::State::fault_reaction_active) {
    fault_reported_ = false;
    error_code_ = 0;
    emcy(canopen::kEmcyReset, now_ns);
  }
  if (drive_.state() == cia402::State::fault_reaction_active) drive_.step(controlword_, fault);
  if (drive_.operation_enabled() && command_timed_out(now_ns)) {
    integrate(now_ns);
    drive_.quick_stop();
    watchdog_tripped_ = true;
    ++counters_.watchdog_trips;
    emcy(canopen::kEmcyHostTimeout, now_ns);
  }
  integrate(now_ns);
}

void SimArm::publish() noexcept {
  drive_pub_.store(drive_.state());
  for (int j = 0; j < arm::kJoints; ++j) pos_pub_[j].store(pos_[j], std::memory_order_relaxed);
}

}  // namespace crease::drivers::sim
