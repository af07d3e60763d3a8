#include "drivers/can/socketcand_protocol.h"

#include <array>
#include <cstring>

namespace crease::drivers::socketcand {
namespace {
constexpr char kHex[] = "0123456789ABCDEF";

int hexv(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Whitespace separates tokens. A table, not four comparisons per character: the tokenizer
// reads every byte of a message, and under the fuzzer each comparison is a call into it.
constexpr auto kSpace = [] {
  std::array<bool, 256> t{};
  t[' '] = t['\t'] = t['\r'] = t['\n'] = true;
  return t;
}();
bool is_space(char c) noexcept {
  return kSpace.data()[static_cast<unsigned char>(c)];
}

// Next whitespace-separated token of s starting at *pos (a pointer scan: one bound check a
// character, no substr).
std::string_view token(std::string_view s, std::size_t* pos) noexcept {
  const char* p = s.data() + *pos;
  const char* const end = s.data() + s.size();
  while (p != end && is_space(*p)) ++p;
  const char* const b = p;
  while (p != end && !is_space(*p)) ++p;
  *pos = static_cast<std::size_t>(p - s.data());
  return {b, static_cast<std::size_t>(p - b)};
}

bool parse_hex(std::string_view t, std::uint32_t max_digits, std::uint32_t* out) noexcept {
  if (t.empty() || t.size() > max_digits) return false;
  std::uint32_t v = 0;
  for (char c : t) {
    const int h = hexv(c);
    if (h < 0) return false;
    v = (v << 4) | static_cast<std::uint32_t>(h);
  }
  *out = v;
  return true;
}
}  // namespace

bool parse_message(std::string_view s, Message& out) noexcept {
  out = Message{};
  if (s.size() > kMaxMessage) return false;  // longer than any message (StreamSplitter drops those)
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  if (s.size() < 3 || s.front() != '<' || s.back() != '>') return false;
  s = s.substr(1, s.size() - 2);
  std::size_t pos = 0;
  const std::string_view word = token(s, &pos);
  if (word == "open") {
    const std::string_view iface = token(s, &pos);
    if (iface.empty() || iface.size() >= sizeof(out.interface) || !token(s, &pos).empty()) return false;
    std::memcpy(out.interface, iface.data(), iface.size());
    out.command = Command::open;
    return true;
  }
  if (word == "rawmode" || word == "echo") {
    if (!token(s, &pos).empty()) return false;
    out.command = word == "rawmode" ? Command::rawmode : Command::echo;
    return true;
  }
  if (word == "send") {
    std::uint32_t id = 0, len = 0;
    const std::string_view ids = token(s, &pos);
    if (!parse_hex(ids, 8, &id) || !parse_hex(token(s, &pos), 2, &len) || len > 8) return false;
    const bool ext = ids.size() > 3 || id > CAN_SFF_MASK;
    if (id > CAN_EFF_MASK) return false;
    out.frame.can_id = ext ? (id | CAN_EFF_FLAG) : id;
    out.frame.len = static_cast<std::uint8_t>(len);
    for (std::uint32_t i = 0; i < len; ++i) {
      std::uint32_t b = 0;
      if (!parse_hex(token(s, &pos), 2, &b)) return false;
      out.frame.data[i] = static_cast<std::uint8_t>(b);
    }
    if (!token(s, &pos).empty()) return false;
    out.command = Command::send;
    return true;
  }
  out.command = Command::unknown;
  return !word.empty();
}

std::size_t format_frame(const CanFrame& f, std::int64_t ts, char* buf, std::size_t cap) noexcept {
  if (f.is_fd() || f.is_error() || f.len > 8) return 0;
  char tmp[96];
  std::size_t n = 0;
  auto put = [&](const char* s) {
    while (*s) tmp[n++] = *s++;
  };
  put(" < frame ");  // leading space: see SocketcandBridge (python-can 4.1 buffer handling)
  const std::uint32_t id = f.id();
  const int digits = f.is_extended() ? 8 : 3;
  for (int i = digits - 1; i >= 0; --i) tmp[n++] = kHex[(id >> (4 * i)) & 0xF];
  tmp[n++] = ' ';
  if (ts < 0) ts = 0;
  char num[24];
  int k = 0;
  std::uint64_t sec = static_cast<std::uint64_t>(ts / 1'000'000'000);
  do {
    num[k++] = static_cast<char>('0' + sec % 10);
    sec /= 10;
  } while (sec);
  while (k) tmp[n++] = num[--k];
  tmp[n++] = '.';
  std::uint64_t usec = static_cast<std::uint64_t>((ts % 1'000'000'000) / 1000);
  for (int i = 5; i >= 0; --i) {
    tmp[n + static_cast<std::size_t>(i)] = static_cast<char>('0' + usec % 10);
    usec /= 10;
  }
  n += 6;
  tmp[n++] = ' ';
  for (std::uint8_t i = 0; i < f.len; ++i) {
    tmp[n++] = kHex[f.data[i] >> 4];
    tmp[n++] = kHex[f.data[i] & 0xF];
  }
  put(" >");
  if (n > cap) return 0;
  std::memcpy(buf, tmp, n);
  return n;
}

std::size_t StreamSplitter::feed(const char* data, std::size_t n, const char** msg, std::size_t* len) noexcept {
  // Run by run: memchr finds the next '<' (outside a message) or '>' (inside one).
  *msg = nullptr;
  *len = 0;
  std::size_t i = 0;
  while (i < n) {
    if (!in_message_) {
      const auto* lt = static_cast<const char*>(std::memchr(data + i, '<', n - i));
      if (!lt) return n;
      i = static_cast<std::size_t>(lt - data) + 1;
      in_message_ = true;
      overflow_ = false;
      buf_[0] = '<';
      n_ = 1;
      continue;
    }
    const auto* gt = static_cast<const char*>(std::memchr(data + i, '>', n - i));
    const std::size_t end = gt ? static_cast<std::size_t>(gt - data) + 1 : n;  // [i, end) is message
    const std::size_t k = end - i, room = sizeof(buf_) - n_;
    std::memcpy(buf_ + n_, data + i, k <= room ? k : room);
    if (k <= room) {
      n_ += k;
    } else {
      n_ = sizeof(buf_);
      overflow_ = true;
    }
    i = end;
    if (gt) {
      in_message_ = false;
      if (overflow_) {
        ++dropped_;
        continue;
      }
      *msg = buf_;
      *len = n_;
      return i;
    }
  }
  return n;
}

}  // namespace crease::drivers::socketcand
