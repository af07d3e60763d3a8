// SimHand: the device side of the hand protocol (drivers/README.md §2-3) with simple
// dynamics: each joint tracks its target with a first-order lag (time constant tau_s);
// an external joint torque deflects it by torque / stiffness; in the safe state (20 ms
// without a valid command, or flag enable = 0) it holds its position with zero stiffness.
// With external_positions (a simulated world owns the hand's physics, plugins/sim_world) the
// device has no dynamics of its own: its status frames report the joint angles the world set
// (set_joint_positions), and the world reads what the host commanded (target, stiffness,
// limp). The CANopen services and step() come from CanopenDevice.
#pragma once

#include <atomic>

#include "drivers/protocol/hand_protocol.h"
#include "drivers/simdevice/canopen_device.h"

namespace crease::drivers::sim {

struct SimHandConfig {
  std::uint8_t node = 1;
  double tau_s = 0.02;
  bool pressure_sensors = false;           // left hand: 5 air-pressure sensors (TPDO2)
  std::int64_t watchdog_ns = 20'000'000;   // no valid command for this long -> safe state
  std::int64_t heartbeat_period_ns = 100'000'000;
  bool auto_start = false;                 // enter operational without an NMT start
  bool external_positions = false;         // positions from set_joint_positions, no own dynamics
};

using SimHandCounters = SimDeviceCounters;

class SimHand final : public CanopenDevice {
 public:
  SimHand(CanBus& bus, const SimHandConfig& cfg) noexcept;
  // World inputs (any thread): external torque on a joint (N m), fingertip pressures (kPa).
  void set_external_torque(int joint, float torque_nm) noexcept { ext_torque_[joint].store(torque_nm); }
  void set_pressure(int sensor, float kpa) noexcept { pressure_[sensor].store(kpa); }
  // The world's side of external_positions, from the thread that calls step() (between two
  // steps): the joint angles the next status frames report (rad), and what the host commands:
  // targets (rad), stiffness (N m/rad, the last stiffness frame; 5 until one arrived), and
  // whether the hand is limp (safe state or not enabled: hold where it is, zero force).
  void set_joint_positions(const float (&rad)[hand::kJoints]) noexcept;
  [[nodiscard]] float commanded_target(int j) const noexcept { return target_[j]; }
  [[nodiscard]] float commanded_stiffness(int j) const noexcept { return stiffness_[j]; }
  [[nodiscard]] bool limp() const noexcept { return safe_ || !enabled_; }
  // Observers for tests and the world (any thread): published at the end of every step().
  [[nodiscard]] bool in_safe_state() const noexcept { return safe_pub_.load(); }
  [[nodiscard]] canopen::NmtState nmt() const noexcept { return nmt_pub_.load(); }
  [[nodiscard]] float position(int j) const noexcept { return pos_pub_[j].load(); }

 private:
  void on_pdo(const CanFrame& f, std::int64_t now_ns) noexcept override;
  void integrate(std::int64_t now_ns) noexcept override;
  void send_status() noexcept override;
  void supervise(std::int64_t now_ns) noexcept override;
  void publish() noexcept override;

  SimHandConfig cfg_;
  bool safe_ = true;
  bool enabled_ = false;
  std::uint16_t stiff_seq_ = 0;
  float pos_[hand::kJoints] = {};
  float target_[hand::kJoints] = {};
  float stiffness_[hand::kJoints] = {};
  std::atomic<float> ext_torque_[hand::kJoints] = {};
  std::atomic<float> pressure_[hand::kPressureSensors] = {};
  std::atomic<bool> safe_pub_{true};
  std::atomic<canopen::NmtState> nmt_pub_{canopen::NmtState::boot_up};
  std::atomic<float> pos_pub_[hand::kJoints] = {};
};

}  // namespace crease::drivers::sim
