// The arm protocol over CAN FD (drivers/README.md, "Arm"): 7 joints behind one CiA 402-like
// drive node. Host -> arm: Command (0x200 + node, FD 64 B: controlword, mode, position and
// velocity set points). Arm -> host after every SYNC: Status (0x180 + node, FD 64 B:
// statusword, positions, velocities). Payloads end with CRC-32C. RT-safe.
#pragma once

#include <cstdint>

#include "drivers/can/can_frame.h"
#include "drivers/protocol/canopen.h"
#include "drivers/protocol/decode_result.h"

namespace crease::drivers::arm {

inline constexpr int kJoints = 7;
inline constexpr double kPositionUnitRad = 1e-6;   // i32 micro-radians
inline constexpr double kVelocityUnitRadS = 1e-3;  // i16 milli-radians per second (+-32.7 rad/s)
inline constexpr std::size_t kCommandLen = 64, kStatusLen = 64;

// Modes of operation (CiA 402 object 0x6060 values).
inline constexpr std::uint8_t kModeCyclicPosition = 8;  // CSP: track position set points
inline constexpr std::uint8_t kModeCyclicVelocity = 9;  // CSV: track velocity set points

struct Command {
  std::uint16_t seq = 0;
  std::uint16_t controlword = 0;
  std::uint8_t mode = kModeCyclicPosition;
  float position_rad[kJoints] = {};
  float velocity_rad_s[kJoints] = {};
};

struct Status {
  std::uint16_t cmd_seq = 0;      // seq of the last command applied
  std::uint16_t statusword = 0;
  std::uint32_t device_time_us = 0;
  std::uint8_t valid = 0;         // bit j: joint j measured this cycle
  std::uint8_t mode = 0;          // mode in effect
  std::uint16_t error_code = 0;   // CiA 402 0x603F, 0 = none
  std::uint8_t sync_counter = 0;
  canopen::NmtState nmt = canopen::NmtState::boot_up;
  float position_rad[kJoints] = {};
  float velocity_rad_s[kJoints] = {};
};

[[nodiscard]] CanFrame encode(std::uint8_t node, const Command& c) noexcept;
[[nodiscard]] CanFrame encode(std::uint8_t node, const Status& s) noexcept;
[[nodiscard]] Decode decode(std::uint8_t node, const CanFrame& f, Command& out) noexcept;
[[nodiscard]] Decode decode(std::uint8_t node, const CanFrame& f, Status& out) noexcept;

}  // namespace crease::drivers::arm
