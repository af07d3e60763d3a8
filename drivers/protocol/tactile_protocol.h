// The tactile matrix over serial (drivers/README.md, "Tactile"): framed with
// serial_framing.h. Host -> sensor: Start (type 0x01: rate_hz u16), Stop (type 0x02).
// Sensor -> host: Sample (type 0x10): device time, 5 fingertips x 34 taxels of u16 pressure.
#pragma once

#include <cstdint>
#include <span>

#include "drivers/protocol/decode_result.h"
#include "drivers/serial/serial_framing.h"

namespace crease::drivers::tactile {

inline constexpr int kFingertips = 5;
inline constexpr int kTaxels = 34;                 // per fingertip (seed 000, Section V)
inline constexpr double kPressureUnitKpa = 0.01;   // u16 per taxel
inline constexpr std::uint8_t kTypeStart = 0x01, kTypeStop = 0x02, kTypeSample = 0x10;
inline constexpr std::size_t kSampleLen = 8 + 2 * kFingertips * kTaxels;  // 348 bytes

struct Sample {
  std::uint32_t device_time_us = 0;
  std::uint16_t sample_counter = 0;
  std::uint8_t valid = 0;  // bit f: fingertip f delivered data
  float pressure_kpa[kFingertips][kTaxels] = {};
};

// Payload encoders: return the payload length written into out (>= kSampleLen bytes).
[[nodiscard]] std::size_t encode_sample(const Sample& s, std::span<std::uint8_t> out) noexcept;
[[nodiscard]] Decode decode_sample(const SerialFrame& f, Sample& out) noexcept;
[[nodiscard]] std::size_t encode_start(std::uint16_t rate_hz, std::span<std::uint8_t> out) noexcept;
[[nodiscard]] Decode decode_start(const SerialFrame& f, std::uint16_t& rate_hz) noexcept;

}  // namespace crease::drivers::tactile
