// Little-endian field access and the CRC-32C trailer shared by the frame codecs. RT-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include "drivers/serial/crc32c.h"

namespace crease::drivers::wire {

inline void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (int k = 0; k < 4; ++k) p[k] = static_cast<std::uint8_t>(v >> (8 * k));
}
inline void put_i16(std::uint8_t* p, std::int16_t v) noexcept { put_u16(p, static_cast<std::uint16_t>(v)); }
inline void put_i32(std::uint8_t* p, std::int32_t v) noexcept { put_u32(p, static_cast<std::uint32_t>(v)); }
inline std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | p[1] << 8);
}
inline std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  std::uint32_t v = 0;
  for (int k = 0; k < 4; ++k) v |= static_cast<std::uint32_t>(p[k]) << (8 * k);
  return v;
}
inline std::int16_t get_i16(const std::uint8_t* p) noexcept { return static_cast<std::int16_t>(get_u16(p)); }
inline std::int32_t get_i32(const std::uint8_t* p) noexcept { return static_cast<std::int32_t>(get_u32(p)); }

// Writes CRC-32C of p[0..len-4) into the last 4 bytes.
inline void seal(std::uint8_t* p, std::size_t len) noexcept { put_u32(p + len - 4, crc32c({p, len - 4})); }
inline bool sealed_ok(const std::uint8_t* p, std::size_t len) noexcept {
  return get_u32(p + len - 4) == crc32c({p, len - 4});
}

// Saturating conversion of a physical value to fixed point (value / unit, rounded).
template <typename T>
inline T to_fixed(double value, double unit) noexcept {
  const double x = value / unit;
  constexpr double lo = static_cast<double>(std::numeric_limits<T>::min());
  constexpr double hi = static_cast<double>(std::numeric_limits<T>::max());
  if (!(x == x)) return 0;  // NaN -> 0
  if (x <= lo) return std::numeric_limits<T>::min();
  if (x >= hi) return std::numeric_limits<T>::max();
  return static_cast<T>(x < 0 ? x - 0.5 : x + 0.5);
}

// A little-endian integer of type T (u8..u32 / i8..i32) at p.
template <typename T>
inline T get_le(const std::uint8_t* p) noexcept {
  static_assert(sizeof(T) <= 4);
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < sizeof(T); ++k) v |= static_cast<std::uint32_t>(p[k]) << (8 * k);
  return static_cast<T>(v);
}
template <typename T>
inline void put_le(std::uint8_t* p, T v) noexcept {
  static_assert(sizeof(T) <= 4);
  const auto u = static_cast<std::uint32_t>(v);
  for (std::size_t k = 0; k < sizeof(T); ++k) p[k] = static_cast<std::uint8_t>(u >> (8 * k));
}

// n physical values as consecutive fixed-point fields of type T (unit per count, saturated).
template <typename T, typename F>
inline void put_fixed_array(std::uint8_t* p, const F* values, int n, double unit) noexcept {
  for (int k = 0; k < n; ++k) put_le<T>(p + sizeof(T) * static_cast<std::size_t>(k), to_fixed<T>(values[k], unit));
}
template <typename T, typename F>
inline void get_fixed_array(const std::uint8_t* p, F* values, int n, double unit) noexcept {
  for (int k = 0; k < n; ++k)
    values[k] = static_cast<F>(get_le<T>(p + sizeof(T) * static_cast<std::size_t>(k)) * unit);
}

}  // namespace crease::drivers::wire
