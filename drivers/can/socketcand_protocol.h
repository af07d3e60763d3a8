// The socketcand ASCII protocol (rawmode, classic frames), as spoken by socketcand and
// python-can's "socketcand" interface: messages "< word args... >" over TCP.
//   server: "< hi >", "< ok >", "< frame ID SEC.USEC HEXDATA >", "< error TEXT >"
//   client: "< open IFACE >", "< rawmode >", "< send ID LEN B0 B1 ... >", "< echo >"
// Pure parsing/formatting, RT-safe, fuzzed (tests/fuzz).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drivers/can/can_frame.h"

namespace crease::drivers::socketcand {

inline constexpr std::size_t kMaxMessage = 256;

enum class Command : std::uint8_t { open, rawmode, send, echo, unknown };

struct Message {
  Command command = Command::unknown;
  char interface[16] = {};  // open: interface name
  CanFrame frame;           // send: the frame
};

// Parses one complete message "< ... >" (surrounding whitespace allowed). False if malformed
// or longer than kMaxMessage (unknown words give Command::unknown and true).
[[nodiscard]] bool parse_message(std::string_view text, Message& out) noexcept;

// Formats "< frame ID SEC.USEC HEXDATA >" for a classic frame; returns length, 0 if it does
// not fit or the frame is FD / error.
std::size_t format_frame(const CanFrame& f, std::int64_t timestamp_ns, char* buf, std::size_t cap) noexcept;

// Splits a TCP byte stream into messages: push bytes, pop complete "<...>" messages.
// Bytes outside "<...>" are skipped; a message longer than kMaxMessage is dropped.
class StreamSplitter {
 public:
  // Consumes bytes until one message completes; returns bytes consumed. *msg/*len point into
  // an internal buffer valid until the next call.
  std::size_t feed(const char* data, std::size_t n, const char** msg, std::size_t* len) noexcept;
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }

 private:
  char buf_[kMaxMessage];
  std::size_t n_ = 0;
  bool in_message_ = false, overflow_ = false;
  std::uint64_t dropped_ = 0;
};

}  // namespace crease::drivers::socketcand
