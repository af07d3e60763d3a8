// libFuzzer target: the COBS/CRC-32C deframer and the tactile decoder behind it.
// Invariant: an accepted frame re-encodes to bytes that deframe to the same frame.
// Speed: a run costs the instrumented decoding per input byte, and stream inputs grow (each
// further frame or run is new coverage) to the 4096 bytes libFuzzer allows: that, not set-up,
// made this target ~30x slower than the CAN decoders. So only the first kMaxInput bytes count
// (tools/fuzz passes the same -max_len): room for the longest frame or an over-long run and
// more; and the input goes through feed() (run by run, as SerialPort reads; push() on every
// byte gives the same result, tests/drivers/serial/serial_framing_test.cpp). The fuzz binaries
// are built at -O2 with only the code they reach (tests/fuzz/CMakeLists.txt).
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "drivers/protocol/tactile_protocol.h"
#include "drivers/serial/serial_framing.h"

using namespace crease::drivers;

constexpr std::size_t kMaxInput = 600;
static_assert(kMaxInput > kSerialMaxWire + 2);

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > kMaxInput) size = kMaxInput;
  // Kept from run to run and reset (a fresh deframer and two frames zeroed 1.5 kB per run).
  static SerialDeframer d, d2;
  static SerialFrame f, g;
  d.reset();
  for (std::size_t off = 0; off < size;) {
    bool got = false;
    off += d.feed({data + off, size - off}, f, &got);
    if (!got) continue;
    tactile::Sample s;
    (void)tactile::decode_sample(f, s);
    std::uint16_t rate;
    (void)tactile::decode_start(f, rate);
    std::uint8_t wire[kSerialMaxWire];
    const std::size_t n = serial_encode(f.seq, f.type, f.bytes(), wire);
    d2.reset();
    bool again = false;
    for (std::size_t k = 0; k < n && !again;) k += d2.feed({wire + k, n - k}, g, &again);
    if (!again || g.len != f.len || g.type != f.type || std::memcmp(g.payload, f.payload, f.len) != 0) __builtin_trap();
  }
  std::uint8_t out[kSerialMaxWire * 2];
  const long m = cobs_decode({data, size}, {out, sizeof(out)});
  (void)m;
  return 0;
}
