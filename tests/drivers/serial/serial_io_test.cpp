// FdSerialIo over a pty: waits for bytes, reads what is waiting, writes, and is woken out of
// an otherwise endless wait; over a Unix socket link, its peer's close is a hang-up.
#include "drivers/serial/serial_io.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <thread>
#include <vector>

#include "drivers/serial/serial_port.h"
#include "drivers/serial/unix_link.h"

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

// The simulated robot's socket link (unix_link.h): bytes both ways as on a tty; once the peer
// closed, a read is a hang-up (-EIO after the wait, as a pty's POLLHUP: the reader does not
// spin on end of file) and a write fails with EPIPE, never a SIGPIPE.
TEST_CASE("FdSerialIo: on a Unix socket link its peer's close is a hang-up, and writing to it raises no SIGPIPE") {
  const std::string path = "/tmp/crease-t-io-" + std::to_string(::getpid());
  UnixLinkListener listener(path);
  const int host = connect_unix_link(path);
  int device = -1;
  for (int i = 0; i < 1000 && device < 0; ++i) device = listener.accept_rt();
  REQUIRE(device >= 0);
  FdSerialIo io(host);
  std::uint8_t buf[64];
  CHECK(io.read_wait(buf, 1) == 0);  // nothing written: the wait times out
  const std::uint8_t msg[3] = {4, 5, 6};
  REQUIRE(::write(device, msg, 3) == 3);
  CHECK(io.read_wait(buf, 1000) == 3);
  CHECK(io.write(msg) == 3);
  CHECK(::read(device, buf, sizeof buf) == 3);
  CHECK_FALSE(unix_link_hung_up(device));
  ::close(device);
  CHECK(io.read_wait(buf, 5) == -EIO);
  CHECK(io.read_wait(buf, 5) == -EIO);
  CHECK(io.write(msg) == -EPIPE);  // the process is still here: no SIGPIPE
  ::close(host);
  // And the device's side: its peer gone, it sees the hang-up and its frames fail, counted.
  const int host2 = connect_unix_link(path);
  int device2 = -1;
  for (int i = 0; i < 1000 && device2 < 0; ++i) device2 = listener.accept_rt();
  REQUIRE(device2 >= 0);
  ::close(host2);
  CHECK(unix_link_hung_up(device2));
  SerialLink sensor(device2);
  const std::uint8_t payload[2] = {1, 2};
  CHECK_FALSE(sensor.send_from_rt(0x10, payload));
  CHECK(sensor.tx_stats().tx_short == 1);
  ::close(device2);
}
