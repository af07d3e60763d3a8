// SimArm: the device side of the arm protocol (drivers/README.md §4): a CiA 402 drive with 7
// joints. In operation enabled, mode 8 tracks the position set point with a first-order lag,
// mode 9 integrates a lagged velocity set point; quick stop decelerates to rest; the 20 ms
// watchdog forces quick stop. The CANopen services and step() come from CanopenDevice.
#pragma once

#include <atomic>

#include "drivers/protocol/arm_protocol.h"
#include "drivers/protocol/cia402.h"
#include "drivers/simdevice/canopen_device.h"

namespace crease::drivers::sim {

struct SimArmConfig {
  std::uint8_t node = 10;
  double tau_s = 0.03;
  std::int64_t watchdog_ns = 20'000'000;
  std::int64_t heartbeat_period_ns = 100'000'000;
  bool auto_start = false;
  float initial_position_rad[arm::kJoints] = {};  // where the joints are at power-up
};

using SimArmCounters = SimDeviceCounters;

class SimArm final : public CanopenDevice {
 public:
  SimArm(CanBus& bus, const SimArmConfig& cfg) noexcept;
  // A joint fault (over-temperature, encoder error...): CiA 402 fault until reset and cleared.
  void set_fault(bool f) noexcept { fault_.store(f); }
  // Observers (any thread): published at the end of every step().
  [[nodiscard]] cia402::State drive_state() const noexcept { return drive_pub_.load(); }
  [[nodiscard]] float position(int j) const noexcept { return pos_pub_[j].load(); }

 private:
  void on_pdo(const CanFrame& f, std::int64_t now_ns) noexcept override;
  void integrate(std::int64_t now_ns) noexcept override;
  void send_status() noexcept override;
  void supervise(std::int64_t now_ns) noexcept override;
  void publish() noexcept override;

  SimArmConfig cfg_;
  cia402::Machine drive_;
  bool watchdog_tripped_ = false, fault_reported_ = false;
  std::uint16_t controlword_ = 0, error_code_ = 0;
  std::uint8_t mode_ = arm::kModeCyclicPosition;
  float pos_[arm::kJoints] = {}, vel_[arm::kJoints] = {};
  float pos_sp_[arm::kJoints] = {}, vel_sp_[arm::kJoints] = {};
  std::atomic<bool> fault_{false};
  std::atomic<cia402::State> drive_pub_{cia402::State::not_ready_to_switch_on};
  std::atomic<float> pos_pub_[arm::kJoints] = {};
};

}  // namespace crease::drivers::sim
