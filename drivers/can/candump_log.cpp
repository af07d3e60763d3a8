#include "drivers/can/candump_log.h"

#include <poll.h>
#include <time.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "rt/clock.h"

namespace crease::drivers {
namespace {
constexpr char kHex[] = "0123456789ABCDEF";

int hex_val(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Writes an unsigned decimal; returns chars written.
std::size_t put_dec(char* p, std::uint64_t v, int min_digits) noexcept {
  char tmp[24];
  int n = 0;
  do {
    tmp[n++] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0 || n < min_digits);
  for (int i = 0; i < n; ++i) p[i] = tmp[n - 1 - i];
  return static_cast<std::size_t>(n);
}

}  // namespace

std::size_t format_candump_line(const CandumpEntry& e, char* buf, std::size_t cap) noexcept {
  char tmp[256];
  std::size_t n = 0;
  const std::int64_t ts = e.timestamp_ns < 0 ? 0 : e.timestamp_ns;
  tmp[n++] = '(';
  n += put_dec(tmp + n, static_cast<std::uint64_t>(ts / 1'000'000'000), 1);
  tmp[n++] = '.';
  n += put_dec(tmp + n, static_cast<std::uint64_t>((ts % 1'000'000'000) / 1000), 6);
  tmp[n++] = ')';
  tmp[n++] = ' ';
  const std::size_t il = strnlen(e.interface, sizeof(e.interface) - 1);
  std::memcpy(tmp + n, il ? e.interface : "can0", il ? il : 4);
  n += il ? il : 4;
  tmp[n++] = ' ';
  const CanFrame& f = e.frame;
  const bool eff = f.is_extended() || f.is_error();
  const std::uint32_t id = f.is_error() ? (f.can_id & (CAN_ERR_MASK | CAN_ERR_FLAG)) : f.id();
  const int digits = eff ? 8 : 3;
  for (int i = digits - 1; i >= 0; --i) tmp[n++] = kHex[(id >> (4 * i)) & 0xF];
  tmp[n++] = '#';
  if (f.is_fd()) {
    tmp[n++] = '#';
    tmp[n++] = kHex[f.flags & 0x3];  // BRS/ESI nibble, as candump prints it
  } else if (f.is_rtr()) {
    tmp[n++] = 'R';
    if (f.len > 0) tmp[n++] = kHex[f.len & 0xF];
  }
  if (!f.is_rtr()) {
    const std::uint8_t len = f.len > 64 ? 64 : f.len;
    for (std::uint8_t i = 0; i < len; ++i) {
      tmp[n++] = kHex[f.data[i] >> 4];
      tmp[n++] = kHex[f.data[i] & 0xF];
    }
  }
  if (n > cap) return 0;
  std::memcpy(buf, tmp, n);
  return n;
}

bool parse_candump_line(std::string_view s, CandumpEntry& out) noexcept {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.remove_suffix(1);
  out = CandumpEntry{};
  if (s.size() < 4 || s[0] != '(') return false;
  std::size_t i = 1;
  std::uint64_t sec = 0, frac = 0;
  int sec_digits = 0, frac_digits = 0;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9' && sec_digits < 12) sec = sec * 10 + static_cast<std::uint64_t>(s[i++] - '0'), ++sec_digits;
  if (sec_digits == 0 || i >= s.size() || s[i] != '.') return false;
  ++i;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9' && frac_digits < 9) frac = frac * 10 + static_cast<std::uint64_t>(s[i++] - '0'), ++frac_digits;
  if (frac_digits == 0 || i >= s.size() || s[i] != ')') return false;
  for (int d = frac_digits; d < 9; ++d) frac *= 10;
  out.timestamp_ns = static_cast<std::int64_t>(sec * 1'000'000'000 + frac);
  ++i;
  if (i >= s.size() || s[i] != ' ') return false;
  ++i;
  std::size_t start = i;
  while (i < s.size() && s[i] != ' ') ++i;
  const std::size_t il = i - start;
  if (il == 0 || il >= sizeof(out.interface) || i >= s.size()) return false;
  std::memcpy(out.interface, s.data() + start, il);
  ++i;
  start = i;
  std::uint32_t id = 0;
  while (i < s.size() && s[i] != '#') {
    const int v = hex_val(s[i]);
    if (v < 0 || i - start >= 8) return false;
    id = (id << 4) | static_cast<std::uint32_t>(v);
    ++i;
  }
  const std::size_t id_digits = i - start;
  if (i >= s.size() || (id_digits != 3 && id_digits != 8)) return false;
  ++i;  // '#'
  CanFrame& f = out.frame;
  if (id_digits == 8) {
    if (id & CAN_ERR_FLAG) {
      f.can_id = id & (CAN_ERR_FLAG | CAN_ERR_MASK);
    } else {
      if (id > CAN_EFF_MASK) return false;
      f.can_id = id | CAN_EFF_FLAG;
    }
  } else {
    if (id > CAN_SFF_MASK) return false;
    f.can_id = id;
  }
  std::size_t max_len = 8;
  if (i < s.size() && s[i] == '#') {
    ++i;
    if (i >= s.size()) return false;
    const int fl = hex_val(s[i++]);
    if (fl < 0) return false;
    f.flags = static_cast<std::uint8_t>(CANFD_FDF | (fl & 0x3));
    max_len = 64;
  } else if (i < s.size() && s[i] == 'R') {
    ++i;
    f.can_id |= CAN_RTR_FLAG;
    if (i < s.size()) {
      const int l = hex_val(s[i++]);
      if (l < 0 || l > 8 || i != s.size()) return false;
      f.len = static_cast<std::uint8_t>(l);
    }
    return true;
  }
  const std::size_t hex = s.size() - i;
  if (hex % 2 != 0 || hex / 2 > max_len) return false;
  for (std::size_t k = 0; k < hex / 2; ++k) {
    const int hi = hex_val(s[i + 2 * k]), lo = hex_val(s[i + 2 * k + 1]);
    if (hi < 0 || lo < 0) return false;
    f.data[k] = static_cast<std::uint8_t>(hi << 4 | lo);
  }
  f.len = static_cast<std::uint8_t>(hex / 2);
  if (f.is_fd() && !can_fd_valid_len(f.len)) return false;
  return true;
}

CandumpWriter::CandumpWriter(const std::string& path) : path_(path), f_(std::fopen(path.c_str(), "w")) {
  if (!f_) throw std::runtime_error("candump log '" + path + "': cannot open for writing: " + std::strerror(errno));
}
CandumpWriter::~CandumpWriter() { std::fclose(f_); }

void CandumpWriter::write(const CandumpEntry& e) {
  char buf[256];
  const std::size_t n = format_candump_line(e, buf, sizeof(buf) - 1);
  buf[n] = '\n';
  if (std::fwrite(buf, 1, n + 1, f_) != n + 1) {
    throw std::runtime_error("candump log '" + path_ + "': write failed: " + std::strerror(errno));
  }
}
void CandumpWriter::flush() { std::fflush(f_); }

CandumpReader::CandumpReader(const std::string& path) : path_(path), f_(std::fopen(path.c_str(), "r")) {
  if (!f_) throw std::runtime_error("candump log '" + path + "': cannot open: " + std::strerror(errno));
}
CandumpReader::~CandumpReader() { std::fclose(f_); }

bool CandumpReader::next(CandumpEntry& out) {
  char buf[512];
  for (;;) {
    if (!std::fgets(buf, sizeof(buf), f_)) return false;
    ++line_;
    std::string_view s(buf);
    if (s.find_first_not_of(" \t\r\n") == std::string_view::npos) continue;  // blank line
    if (!parse_candump_line(s, out)) {
      throw std::runtime_error("candump log '" + path_ + "' line " + std::to_string(line_) +
                               ": not a candump -L frame line");
    }
    return true;
  }
}

namespace {
void sleep_ns(std::int64_t ns) {
  timespec t{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  while (nanosleep(&t, &t) != 0 && errno == EINTR) {
  }
}
// False once the bus's descriptor reports a hang-up or an error (the mock broker is gone,
// the interface vanished).
bool bus_alive(const CanBus& bus) {
  if (bus.fd() < 0) return true;
  pollfd p{bus.fd(), 0, 0};
  return ::poll(&p, 1, 0) <= 0 || (p.revents & (POLLHUP | POLLERR | POLLNVAL)) == 0;
}
}  // namespace

std::size_t replay_candump(CandumpReader& log, CanBus& bus, double speed, ReplayStats* stats,
                           void (*pause_ns)(std::int64_t)) {
  if (!pause_ns) pause_ns = sleep_ns;
  CandumpEntry e;
  ReplayStats st;
  std::int64_t first_log = -1, first_wall = 0;
  while (log.next(e)) {
    if (e.frame.is_error()) continue;  // error frames are bus events, not something to send
    if (speed > 0) {
      if (first_log < 0) {
        first_log = e.timestamp_ns;
        first_wall = rt::now_ns();
      }
      const std::int64_t due = first_wall + static_cast<std::int64_t>(static_cast<double>(e.timestamp_ns - first_log) / speed);
      timespec ts{static_cast<time_t>(due / 1'000'000'000), static_cast<long>(due % 1'000'000'000)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
    }
    for (std::int64_t backoff = 20'000;;) {
      const SendResult r = bus.send(e.frame);
      if (r == SendResult::ok) break;
      if (r != SendResult::no_buffers || !bus_alive(bus)) {
        const char* why = r == SendResult::bus_off ? "bus-off" : r == SendResult::no_buffers ? "the bus is gone" : "send failed";
        throw std::runtime_error("candump replay: bus refused frame " + std::to_string(st.sent) + " (" + why + ": " +
                                 std::strerror(bus.errno_value()) + ")");
      }
      ++st.waits;
      pause_ns(backoff);
      backoff = backoff < 1'000'000 ? 2 * backoff : 1'000'000;
    }
    ++st.sent;
    if (stats) *stats = st;
  }
  if (stats) *stats = st;
  return st.sent;
}

}  // namespace crease::drivers
