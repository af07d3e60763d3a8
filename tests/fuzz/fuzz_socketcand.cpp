// libFuzzer target: the socketcand stream splitter and message parser.
// Invariant: a parsed "send" frame formats and is a classic frame of at most 8 bytes.
// Speed: a run costs the instrumented parsing per input byte, and stream inputs grow (each
// further message is new coverage) to the 4096 bytes libFuzzer allows: that, not set-up, made
// this target ~30x slower than the CAN decoders. So only the first kMaxInput bytes count
// (tools/fuzz passes the same -max_len): a longest message, or an oversized one and the
// message after it. The splitter scans with memchr; parse_message refuses what is longer
// than any message.
#include <cstddef>
#include <cstdint>

#include "drivers/can/socketcand_protocol.h"

using namespace crease::drivers;

constexpr std::size_t kMaxInput = socketcand::kMaxMessage + 64;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > kMaxInput) size = kMaxInput;
  socketcand::StreamSplitter s;
  const char* p = reinterpret_cast<const char*>(data);
  std::size_t off = 0;
  while (off < size) {
    const char* msg;
    std::size_t len;
    off += s.feed(p + off, size - off, &msg, &len);
    if (!msg) continue;
    socketcand::Message m;
    if (socketcand::parse_message({msg, len}, m) && m.command == socketcand::Command::send) {
      if (m.frame.len > 8 || m.frame.is_fd()) __builtin_trap();
      char buf[128];
      if (socketcand::format_frame(m.frame, 0, buf, sizeof(buf)) == 0) __builtin_trap();
    }
  }
  socketcand::Message whole;
  (void)socketcand::parse_message({p, size}, whole);
  return 0;
}
