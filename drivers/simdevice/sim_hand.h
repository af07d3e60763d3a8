// SimHand: the device side of the hand protocol (drivers/README.md §2-3) with simple
// dynamics: each joint tracks its target with a first-order lag (time constant tau_s);
// an external joint torque deflects it by torque / stiffness; in the safe state (20 ms
// without a valid command, or flag enable = 0) it holds its position with zero stiffness.
// The CANopen services and step() come from CanopenDevice.
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
};

using SimHandCounters = SimDeviceCounters;

class SimHand final : public CanopenDevice {
 public:
  SimHand(CanBus& bus, const SimHandConfig& cfg) noexcept;
  // World inputs (any thread): external torque on a joint (N m), fingertip pressures (kPa).
  void set_external_torque(int joint, float torque_nm) noexcept { ext_torque_[joint].store(torque_nm); }
  void set_pressure(int sensor, float kpa) noexcept { pressure_[sensor].store(kpa); }
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
