// Consistent Overhead Byte Stuffing (Cheshire & Baker 1999): encodes bytes so that 0x00 never
// appears, at most 1 byte of overhead per 254 bytes plus 1. 0x00 then delimits frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace crease::drivers {

// Worst-case encoded size of n bytes (without the 0x00 delimiter).
constexpr std::size_t cobs_max_encoded(std::size_t n) noexcept { return n + n / 254 + 1; }

// Encodes in into out; returns the encoded length, or 0 if out is too small. RT-safe.
[[nodiscard]] std::size_t cobs_encode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept;
// Decodes in (no delimiter) into out; returns the decoded length, or -1 if in is not valid
// COBS (a zero byte, a code running past the end) or out is too small. RT-safe.
[[nodiscard]] long cobs_decode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept;

}  // namespace crease::drivers
