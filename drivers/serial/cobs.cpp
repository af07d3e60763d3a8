#include "drivers/serial/cobs.h"

#include <cstring>

namespace crease::drivers {

// Both directions go block by block (memchr finds the zeros, memcpy moves the data), not byte
// by byte: the same result as the byte-wise definition (tests/drivers/serial), at a fraction
// of the work per byte.

std::size_t cobs_encode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept {
  if (out.size() < cobs_max_encoded(in.size())) return 0;
  const std::uint8_t* p = in.data();
  const std::uint8_t* const end = p + in.size();
  std::uint8_t* const dst = out.data();
  std::size_t o = 0;
  for (;;) {
    // One block: up to 254 non-zero bytes, ended by a zero, by the 254th byte or by the end.
    const std::size_t avail = static_cast<std::size_t>(end - p);
    const std::size_t lim = avail < 254 ? avail : 254;
    const auto* zero = lim ? static_cast<const std::uint8_t*>(std::memchr(p, 0, lim)) : nullptr;
    const std::size_t k = zero ? static_cast<std::size_t>(zero - p) : lim;
    dst[o] = static_cast<std::uint8_t>(k + 1);
    if (k) std::memcpy(dst + o + 1, p, k);
    o += k + 1;
    p += k;
    if (zero) {
      ++p;  // the zero is the block's end; a block follows (an empty one at the end)
    } else if (k < 254) {
      return o;  // the end of the input
    }
    // else a full block (code 0xFF, no zero implied); a block follows
  }
}

// Blocks shorter than this are checked and copied byte by byte (frames of small values have
// many), longer ones with memchr and memcpy.
constexpr std::size_t kShortBlock = 16;

long cobs_decode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept {
  const std::uint8_t* p = in.data();
  const std::uint8_t* const end = p + in.size();
  std::uint8_t* o = out.data();
  std::uint8_t* const out_end = o + out.size();
  while (p != end) {
    // A block: code - 1 data bytes, none zero, checked for room once and copied; then the zero
    // the code stands for, unless the code is 0xFF or the block is the last. A zero code wraps
    // k to SIZE_MAX and is refused by the same room check as a block running past the end.
    const std::uint8_t code = *p++;
    const std::size_t k = static_cast<std::size_t>(code) - 1;
    if (k > static_cast<std::size_t>(end - p) || k > static_cast<std::size_t>(out_end - o))
      return -1;
    if (k >= kShortBlock) {
      if (std::memchr(p, 0, k)) return -1;
      std::memcpy(o, p, k);
    } else {
      for (std::size_t i = 0; i < k; ++i) {  // a short block: two library calls cost more
        if (p[i] == 0) return -1;
        o[i] = p[i];
      }
    }
    p += k;
    o += k;
    if (p != end && code != 0xFF) {
      if (o == out_end) return -1;
      *o++ = 0;
    }
  }
  return static_cast<long>(o - out.data());
}

}  // namespace crease::drivers
