// libFuzzer target: the candump -L line parser.
// Invariant: a parsed line formats and parses back to the same frame.
#include <cstddef>
#include <cstdint>

#include "drivers/can/candump_log.h"

using namespace crease::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  CandumpEntry e;
  if (!parse_candump_line({reinterpret_cast<const char*>(data), size}, e)) return 0;
  char buf[256];
  const std::size_t n = format_candump_line(e, buf, sizeof(buf));
  if (n == 0) __builtin_trap();
  CandumpEntry again;
  if (!parse_candump_line({buf, n}, again) || !(again.frame == e.frame)) __builtin_trap();
  return 0;
}
