#include "drivers/serial/serial_port.h"

#include <doctest/doctest.h>
#include <poll.h>
#include <unistd.h>

#include <random>
#include <vector>

using namespace crease::drivers;
using Bytes = std::vector<std::uint8_t>;

namespace {
bool wait_frame(SerialLink& link, SerialFrame& f, int fd, int timeout_ms = 500) {
  for (int i = 0; i < 100; ++i) {
    if (link.poll_from_rt(f)) return true;
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms / 100 + 1) < 0) return false;
  }
  return link.poll_from_rt(f);
}
}  // namespace

TEST_CASE("a bad device path throws, naming the device") {
  CHECK_THROWS_WITH_AS(SerialPort({"/dev/no-such-tty-crease", 115200, false}),
                       doctest::Contains("/dev/no-such-tty-crease"), std::runtime_error);
}

TEST_CASE("framed messages cross a pty with injected garbage: resync within one frame") {
  PtyPair pty;
  SerialPort port({pty.slave_path(), 1'000'000, false});
  SerialLink host(port.fd());
  SerialLink device(pty.master_fd());
  std::mt19937 rng(3);
  SerialFrame f;
  int ok = 0;
  for (int i = 0; i < 200; ++i) {
    Bytes p(1 + rng() % 300);
    for (auto& b : p) b = static_cast<std::uint8_t>(rng());
    if (i % 7 == 3) {  // line noise between frames
      std::uint8_t junk[23];
      for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
      REQUIRE(::write(pty.master_fd(), junk, sizeof(junk)) == sizeof(junk));
    }
    REQUIRE(device.send_from_rt(5, p));
    REQUIRE(wait_frame(host, f, port.fd()));
    CHECK(f.type == 5);
    CHECK(Bytes(f.payload, f.payload + f.len) == p);
    ok += Bytes(f.payload, f.payload + f.len) == p ? 1 : 0;
    // and back the other way
    REQUIRE(host.send_from_rt(6, p));
    REQUIRE(wait_frame(device, f, pty.master_fd()));
    CHECK(Bytes(f.payload, f.payload + f.len) == p);
  }
  CHECK(ok == 200);
  CHECK(host.rx_stats().frames == 200);
  CHECK(host.rx_stats().crc_errors + host.rx_stats().cobs_errors >= 1);  // the junk was seen
}
