// SimArm: the device side of the arm protocol (drivers/README.md §4): a CiA 402 drive with 7
// joints. In operation enabled, mode 8 tracks the position set point with a first-order lag,
// mode 9 integrates a lagged velocity set point; quick stop decelerates to rest; the 20 ms
// watchdog forces quick stop. step() is non-blocking.
#pragma once

#include <atomic>

#include "drivers/can/can_bus.h"
#include "drivers/protocol/arm_protocol.h"
#include "drivers/protocol/cia402.h"

namespace crease::drivers::sim {

struct SimArmConfig {
  std::uint8_t node = 10;
  double tau_s = 0.03;
  std::int64_t watchdog_ns = 20'000'000;
  std::int64_t heartbeat_period_ns = 100'000'000;
  bool auto_start = false;
};

// Written by the device's thread, readable from any thread.
struct SimArmCounters {
  std::atomic<std::uint64_t> commands{0}, bad_crc{0}, syncs{0}, statuses_sent{0}, send_failures{0};
  std::atomic<std::uint64_t> watchdog_trips{0}, emcy_sent{0};
};

class SimArm {
 public:
  SimArm(CanBus& bus, const SimArmConfig& cfg) noexcept;
  void step(std::int64_t now_ns) noexcept;
  // A joint fault (over-temperature, encoder error...): CiA 402 fault until reset and cleared.
  void set_fault(bool f) noexcept { fault_.store(f); }
  void set_silent(bool s) noexcept { silent_.store(s); }
  // Observers (any thread): published at the end of every step().
  [[nodiscard]] cia402::State drive_state() const noexcept { return drive_pub_.load(); }
  [[nodiscard]] float position(int j) const noexcept { return pos_pub_[j].load(); }
  [[nodiscard]] const SimArmCounters& counters() const noexcept { return counters_; }

 private:
  void send(const CanFrame& f) noexcept;
  void on_frame(const CanFrame& f, std::int64_t now_ns) noexcept;
  void integrate(std::int64_t now_ns) noexcept;
  void send_status() noexcept;
  void emcy(std::uint16_t code, std::int64_t now_ns) noexcept;

  CanBus& bus_;
  SimArmConfig cfg_;
  cia402::Machine drive_;
  canopen::NmtState nmt_ = canopen::NmtState::boot_up;
  bool booted_ = false, watchdog_tripped_ = false, fault_reported_ = false;
  std::uint16_t cmd_seq_ = 0, controlword_ = 0, error_code_ = 0;
  std::uint8_t mode_ = arm::kModeCyclicPosition, sync_counter_ = 0;
  std::int64_t last_cmd_ns_ = 0, last_step_ns_ = 0, last_heartbeat_ns_ = 0, t0_ns_ = 0;
  float pos_[arm::kJoints] = {}, vel_[arm::kJoints] = {};
  float pos_sp_[arm::kJoints] = {}, vel_sp_[arm::kJoints] = {};
  std::atomic<bool> fault_{false}, silent_{false};
  std::atomic<cia402::State> drive_pub_{cia402::State::not_ready_to_switch_on};
  std::atomic<float> pos_pub_[arm::kJoints] = {};
  SimArmCounters counters_;
};

}  // namespace crease::drivers::sim
