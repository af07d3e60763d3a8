// SimHand: the device side of the hand protocol (drivers/README.md §2-3) with simple
// dynamics: each joint tracks its target with a first-order lag (time constant tau_s);
// an external joint torque deflects it by torque / stiffness; in the safe state (20 ms
// without a valid command, or flag enable = 0) it holds its position with zero stiffness.
// step() is non-blocking: call it whenever the bus fd is readable and at least every 1 ms.
#pragma once

#include <atomic>

#include "drivers/can/can_bus.h"
#include "drivers/protocol/hand_protocol.h"

namespace crease::drivers::sim {

struct SimHandConfig {
  std::uint8_t node = 1;
  double tau_s = 0.02;
  bool pressure_sensors = false;           // left hand: 5 air-pressure sensors (TPDO2)
  std::int64_t watchdog_ns = 20'000'000;   // no valid command for this long -> safe state
  std::int64_t heartbeat_period_ns = 100'000'000;
  bool auto_start = false;                 // enter operational without an NMT start
};

// Written by the device's thread, readable from any thread.
struct SimHandCounters {
  std::atomic<std::uint64_t> commands{0}, bad_crc{0}, syncs{0}, statuses_sent{0}, send_failures{0};
  std::atomic<std::uint64_t> watchdog_trips{0}, emcy_sent{0};
};

class SimHand {
 public:
  SimHand(CanBus& bus, const SimHandConfig& cfg) noexcept;
  // Processes received frames and advances the dynamics to now_ns.
  void step(std::int64_t now_ns) noexcept;
  // World inputs (any thread): external torque on a joint (N m), fingertip pressures (kPa).
  void set_external_torque(int joint, float torque_nm) noexcept { ext_torque_[joint].store(torque_nm); }
  void set_pressure(int sensor, float kpa) noexcept { pressure_[sensor].store(kpa); }
  // A device that stops answering (but keeps its state), for failure tests.
  void set_silent(bool s) noexcept { silent_.store(s); }
  // Observers for tests and the world (any thread): published at the end of every step().
  [[nodiscard]] bool in_safe_state() const noexcept { return safe_pub_.load(); }
  [[nodiscard]] canopen::NmtState nmt() const noexcept { return nmt_pub_.load(); }
  [[nodiscard]] float position(int j) const noexcept { return pos_pub_[j].load(); }
  [[nodiscard]] const SimHandCounters& counters() const noexcept { return counters_; }

 private:
  void send(const CanFrame& f) noexcept;
  void on_frame(const CanFrame& f, std::int64_t now_ns) noexcept;
  void integrate(std::int64_t now_ns) noexcept;
  void send_status() noexcept;

  CanBus& bus_;
  SimHandConfig cfg_;
  canopen::NmtState nmt_ = canopen::NmtState::boot_up;
  bool safe_ = true;
  bool enabled_ = false;
  bool booted_ = false;
  std::uint16_t cmd_seq_ = 0, stiff_seq_ = 0;
  std::uint8_t sync_counter_ = 0;
  std::int64_t last_cmd_ns_ = 0, last_step_ns_ = 0, last_heartbeat_ns_ = 0, t0_ns_ = 0;
  float pos_[hand::kJoints] = {};
  float target_[hand::kJoints] = {};
  float stiffness_[hand::kJoints] = {};
  std::atomic<float> ext_torque_[hand::kJoints] = {};
  std::atomic<float> pressure_[hand::kPressureSensors] = {};
  std::atomic<bool> silent_{false};
  std::atomic<bool> safe_pub_{true};
  std::atomic<canopen::NmtState> nmt_pub_{canopen::NmtState::boot_up};
  std::atomic<float> pos_pub_[hand::kJoints] = {};
  SimHandCounters counters_;
};

}  // namespace crease::drivers::sim
