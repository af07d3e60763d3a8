// The hand protocol over CAN FD (drivers/README.md, "Hand"): 20 joints per hand.
// Host -> hand: HandCommand (0x200 + node, FD 48 B), HandStiffness (0x300 + node, FD 48 B).
// Hand -> host after every SYNC: HandStatus (0x180 + node, FD 64 B) and, on hands with air
// pressure sensors, HandPressure (0x280 + node, FD 24 B). Every payload ends with CRC-32C.
// Encoders saturate out-of-range values; decoders check identifier, length, FD and CRC. RT-safe.
#pragma once

#include <cstdint>

#include "drivers/can/can_frame.h"
#include "drivers/protocol/canopen.h"
#include "drivers/protocol/decode_result.h"

namespace crease::drivers::hand {

inline constexpr int kJoints = 20;
inline constexpr int kPressureSensors = 5;
inline constexpr double kAngleUnitRad = 1e-4;        // i16: +-3.2767 rad
inline constexpr double kStiffnessUnit = 0.01;       // u16: 0..655.35 N m/rad
inline constexpr double kPressureUnitKpa = 0.01;     // u16: 0..655.35 kPa
inline constexpr std::size_t kCommandLen = 48, kStiffnessLen = 48, kStatusLen = 64, kPressureLen = 24;

// Command flags
inline constexpr std::uint8_t kCmdEnable = 0x01;  // 0: hold position with zero stiffness

struct Command {
  std::uint16_t seq = 0;        // increments every cycle; echoed in Status::cmd_seq
  std::uint8_t flags = 0;
  float target_rad[kJoints] = {};
};

struct Stiffness {
  std::uint16_t seq = 0;        // echoed in Status::stiff_seq
  float stiffness_nm_per_rad[kJoints] = {};
};

// Status flags
inline constexpr std::uint8_t kStatusEnabled = 0x01;
inline constexpr std::uint8_t kStatusWatchdogHold = 0x02;  // no command for 20 ms: holding, zero force
inline constexpr std::uint8_t kStatusFault = 0x04;

struct Status {
  std::uint16_t cmd_seq = 0;     // seq of the last command applied
  std::uint16_t stiff_seq = 0;   // seq of the last stiffness applied
  canopen::NmtState nmt = canopen::NmtState::boot_up;
  std::uint8_t flags = 0;
  std::uint8_t sync_counter = 0;  // counter of the SYNC this status answers
  std::uint32_t device_time_us = 0;
  std::uint32_t valid = 0;        // bit j: position_rad[j] is a fresh measurement
  float position_rad[kJoints] = {};
};

struct Pressure {
  std::uint16_t cmd_seq = 0;
  std::uint8_t sync_counter = 0;
  std::uint8_t valid = 0;         // bit k: pressure_kpa[k] valid
  std::uint32_t device_time_us = 0;
  float pressure_kpa[kPressureSensors] = {};
};

[[nodiscard]] CanFrame encode(std::uint8_t node, const Command& c) noexcept;
[[nodiscard]] CanFrame encode(std::uint8_t node, const Stiffness& s) noexcept;
[[nodiscard]] CanFrame encode(std::uint8_t node, const Status& s) noexcept;
[[nodiscard]] CanFrame encode(std::uint8_t node, const Pressure& p) noexcept;
[[nodiscard]] Decode decode(std::uint8_t node, const CanFrame& f, Command& out) noexcept;
[[nodiscard]] Decode decode(std::uint8_t node, const CanFrame& f, Stiffness& out) noexcept;
[[nodiscard]] Decode decode(std::uint8_t node, const CanFrame& f, Status& out) noexcept;
[[nodiscard]] Decode decode(std::uint8_t node, const CanFrame& f, Pressure& out) noexcept;

}  // namespace crease::drivers::hand
