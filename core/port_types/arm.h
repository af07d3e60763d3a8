// Port payloads `arm_command` and `arm_state`: one 7-joint arm behind a CiA 402-like drive,
// written/read by the arm_driver plugin (drivers/README.md §4). Radians and rad/s.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/hand.h"  // DeviceHealth
#include "core/port_types/payload_layout.h"

namespace crease {

struct ArmCommand {
  static constexpr char kPortType[] = "crease.ArmCommand";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr int kJoints = 7;
  enum Mode : std::uint8_t { position = 0, velocity = 1 };

  std::int64_t timestamp_ns = 0;
  std::uint8_t mode = position;
  float position_rad[kJoints] = {};
  float velocity_rad_s[kJoints] = {};  // set point in velocity mode, feed-forward in position mode

  [[nodiscard]] bool all_finite() const {
    for (int j = 0; j < kJoints; ++j)
      if (!std::isfinite(position_rad[j]) || !std::isfinite(velocity_rad_s[j])) return false;
    return true;
  }
};

struct ArmState {
  static constexpr char kPortType[] = "crease.ArmState";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr int kJoints = 7;

  std::int64_t timestamp_ns = 0;       // CLOCK_MONOTONIC reception time of the status
  std::uint32_t device_time_us = 0;
  std::uint8_t valid = 0;              // bit j: joint j measured
  std::uint8_t drive_state = 0;        // drivers::cia402::State (7 = fault, 4 = operation enabled)
  std::uint16_t error_code = 0;        // drive error code (CiA 402 0x603F), 0 = none
  float position_rad[kJoints] = {};
  float velocity_rad_s[kJoints] = {};
  std::uint8_t fresh = 0;
  DeviceHealth health = DeviceHealth::fault;
  std::uint8_t safe_state = 1;         // 1: the driver is commanding quick stop / fault reset
  std::uint16_t acked_seq = 0;
  std::uint64_t commands_sent = 0;
  std::uint64_t commands_failed = 0;

  [[nodiscard]] bool all_finite() const {
    for (int j = 0; j < kJoints; ++j)
      if (!std::isfinite(position_rad[j]) || !std::isfinite(velocity_rad_s[j])) return false;
    return true;
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(ArmCommand, 72, 8);
CREASE_PORT_PAYLOAD_LAYOUT(ArmState, 96, 8);

}  // namespace crease
