// libFuzzer target: the socketcand stream splitter and message parser.
// Invariant: a parsed "send" frame formats and is a classic frame of at most 8 bytes.
#include <cstddef>
#include <cstdint>

#include "drivers/can/socketcand_protocol.h"

using namespace crease::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
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
