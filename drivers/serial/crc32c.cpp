#include "drivers/serial/crc32c.h"

#include <array>
#include <cstring>

namespace crease::drivers {
namespace {
constexpr std::array<std::uint32_t, 256> make_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    t[i] = c;
  }
  return t;
}
constexpr auto kTable = make_table();

// c is the running (un-inverted) register value.
std::uint32_t crc_table(std::uint32_t c, const std::uint8_t* p, std::size_t n) noexcept {
  for (std::size_t i = 0; i < n; ++i) c = kTable[(c ^ p[i]) & 0xFF] ^ (c >> 8);
  return c;
}

#if defined(__x86_64__)
// SSE4.2 crc32 instruction: 8 bytes per instruction, same polynomial and bit order.
__attribute__((target("sse4.2"))) std::uint32_t crc_sse42(std::uint32_t c, const std::uint8_t* p, std::size_t n) noexcept {
  std::uint64_t c64 = c;
  for (; n >= 8; n -= 8, p += 8) {
    std::uint64_t v;
    std::memcpy(&v, p, 8);
    c64 = __builtin_ia32_crc32di(c64, v);
  }
  std::uint32_t c32 = static_cast<std::uint32_t>(c64);
  for (; n > 0; --n, ++p) c32 = __builtin_ia32_crc32qi(c32, *p);
  return c32;
}
const bool kHaveSse42 = [] {
  __builtin_cpu_init();  // may run before libgcc's own constructor
  return __builtin_cpu_supports("sse4.2") != 0;
}();
#endif
}  // namespace

std::uint32_t crc32c_update(std::uint32_t crc, std::span<const std::uint8_t> bytes) noexcept {
  const std::uint32_t c = ~crc;
#if defined(__x86_64__)
  if (kHaveSse42) return ~crc_sse42(c, bytes.data(), bytes.size());
#endif
  return ~crc_table(c, bytes.data(), bytes.size());
}

std::uint32_t crc32c(std::span<const std::uint8_t> bytes) noexcept { return crc32c_update(0, bytes); }

// For tests: the portable path, whatever the CPU has.
std::uint32_t crc32c_update_portable(std::uint32_t crc, std::span<const std::uint8_t> bytes) noexcept {
  return ~crc_table(~crc, bytes.data(), bytes.size());
}

}  // namespace crease::drivers
