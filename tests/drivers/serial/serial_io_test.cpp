// FdSerialIo over a pty: waits for bytes, reads what is waiting, writes, and is woken out of
// an otherwise endless wait.
#include "drivers/serial/serial_io.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <thread>
#include <vector>

#include "drivers/serial/serial_port.h"

using namespace crease::drivers;

TEST_CASE("FdSerialIo: read_wait returns what the other end wrote, 0 when nothing came, and its writes arrive") {
  PtyPair pty;
  SerialPort port({pty.slave_path(), 1'000'000, false});
  FdSerialIo io(port.fd());
  std::uint8_t buf[64];
  CHECK(io.read_wait(buf, 1) == 0);  // nothing written: the wait times out
  const std::uint8_t msg[3] = {1, 2, 3};
  REQUIRE(::write(pty.master_fd(), msg, 3) == 3);
  long n = 0;
  for (int i = 0; i < 100 && n == 0; ++i) n = io.read_wait(buf, 100);
  REQUIRE(n == 3);
  CHECK(buf[2] == 3);
  const std::uint8_t back[2] = {9, 8};
  CHECK(io.write(back) == 2);
  std::uint8_t got[2] = {};
  long m = 0;
  for (int i = 0; i < 1000 && m <= 0; ++i) {
    m = ::read(pty.master_fd(), got, 2);
    if (m <= 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  CHECK(m == 2);
  CHECK(got[0] == 9);
}

TEST_CASE("FdSerialIo: wake ends a wait on a silent link at once, also a wake sent before the wait") {
  PtyPair pty;
  SerialPort port({pty.slave_path(), 1'000'000, false});
  FdSerialIo io(port.fd());
  std::uint8_t buf[16];
  io.wake();
  CHECK(io.read_wait(buf, 600'000) == 0);  // ten minutes unless the wake ends it (the test's timeout would)
  std::thread t([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    io.wake();
  });
  CHECK(io.read_wait(buf, 600'000) == 0);
  t.join();
}
