// Port payloads `hand_command` and `hand_state`: one 20-joint hand (seed 000, Section V),
// written/read by the hand_driver plugin (drivers/README.md §3 for the wire protocol).
// Joint angles in radians, stiffness in N m/rad, pressures in kPa (names carry the units).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

// Health of a device link as a driver reports it.
enum class DeviceHealth : std::uint8_t {
  ok = 0,        // fresh data every cycle
  degraded = 1,  // data up to a few cycles old (a lost frame, a CRC error)
  fault = 2,     // device silent, bus-off, too many CRC errors or an emergency: safe state commanded
};

struct HandCommand {
  static constexpr char kPortType[] = "crease.HandCommand";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr int kJoints = 20;

  std::int64_t timestamp_ns = 0;                // CLOCK_MONOTONIC time the command was made
  float target_rad[kJoints] = {};
  float stiffness_nm_per_rad[kJoints] = {};     // 0: compliant
  std::uint8_t enable = 0;                      // 0: hold position with zero force

  [[nodiscard]] bool all_finite() const {
    for (int j = 0; j < kJoints; ++j)
      if (!std::isfinite(target_rad[j]) || !std::isfinite(stiffness_nm_per_rad[j])) return false;
    return true;
  }
};

struct HandState {
  static constexpr char kPortType[] = "crease.HandState";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr int kJoints = 20;
  static constexpr int kPressureSensors = 5;

  std::int64_t timestamp_ns = 0;          // CLOCK_MONOTONIC reception time of the status
  std::uint32_t device_time_us = 0;       // the hand's own clock at sampling
  std::uint32_t valid = 0;                // bit j: position_rad[j] measured in that status
  float position_rad[kJoints] = {};
  float pressure_kpa[kPressureSensors] = {};  // hands with air-pressure sensors (left hand)
  std::uint8_t pressure_valid = 0;        // bit k: pressure_kpa[k] valid
  std::uint8_t fresh = 0;                 // 1: this status answers this cycle's SYNC
  DeviceHealth health = DeviceHealth::fault;
  std::uint8_t safe_state = 1;            // 1: the driver is commanding the safe state
  std::uint16_t acked_seq = 0;            // last command sequence number the hand applied
  std::uint64_t commands_sent = 0;
  std::uint64_t commands_failed = 0;      // not acknowledged within 2 cycles

  [[nodiscard]] bool all_finite() const {
    for (float x : position_rad)
      if (!std::isfinite(x)) return false;
    for (float x : pressure_kpa)
      if (!std::isfinite(x)) return false;
    return true;
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(HandCommand, 176, 8);
CREASE_PORT_PAYLOAD_LAYOUT(HandState, 144, 8);

}  // namespace crease
