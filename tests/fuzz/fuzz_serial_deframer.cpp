// libFuzzer target: the COBS/CRC-32C deframer and the tactile decoder behind it.
// Invariant: an accepted frame re-encodes to bytes that deframe to the same frame.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "drivers/protocol/tactile_protocol.h"
#include "drivers/serial/serial_framing.h"

using namespace crease::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  SerialDeframer d;
  SerialFrame f;
  for (std::size_t i = 0; i < size; ++i) {
    if (!d.push(data[i], f)) continue;
    tactile::Sample s;
    (void)tactile::decode_sample(f, s);
    std::uint16_t rate;
    (void)tactile::decode_start(f, rate);
    std::uint8_t wire[kSerialMaxWire];
    const std::size_t n = serial_encode(f.seq, f.type, f.bytes(), wire);
    SerialDeframer d2;
    SerialFrame g;
    bool got = false;
    for (std::size_t k = 0; k < n; ++k) got = d2.push(wire[k], g) || got;
    if (!got || g.len != f.len || g.type != f.type || std::memcmp(g.payload, f.payload, f.len) != 0) __builtin_trap();
  }
  std::uint8_t out[kSerialMaxWire * 2];
  const long m = cobs_decode({data, size}, {out, sizeof(out)});
  (void)m;
  return 0;
}
