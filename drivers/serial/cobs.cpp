#include "drivers/serial/cobs.h"

namespace crease::drivers {

std::size_t cobs_encode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept {
  if (out.size() < cobs_max_encoded(in.size())) return 0;
  std::size_t code_at = 0, o = 1;
  std::uint8_t code = 1;
  for (std::uint8_t b : in) {
    if (b == 0) {
      out[code_at] = code;
      code_at = o++;
      code = 1;
    } else {
      out[o++] = b;
      if (++code == 0xFF) {
        out[code_at] = code;
        code_at = o++;
        code = 1;
      }
    }
  }
  out[code_at] = code;
  return o;
}

long cobs_decode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept {
  std::size_t i = 0, o = 0;
  while (i < in.size()) {
    const std::uint8_t code = in[i++];
    if (code == 0) return -1;
    // The block's code - 1 data bytes: checked for room once, then copied (none may be zero).
    const std::size_t k = static_cast<std::size_t>(code) - 1;
    if (k > in.size() - i || k > out.size() - o) return -1;
    const std::uint8_t* src = in.data() + i;
    std::uint8_t* dst = out.data() + o;
    for (std::size_t j = 0; j < k; ++j) {
      if (src[j] == 0) return -1;
      dst[j] = src[j];
    }
    i += k;
    o += k;
    if (code != 0xFF && i < in.size()) {
      if (o >= out.size()) return -1;
      out[o++] = 0;
    }
  }
  return static_cast<long>(o);
}

}  // namespace crease::drivers
