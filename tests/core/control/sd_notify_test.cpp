// Tests for core/control/sd_notify.h against a datagram socket standing in for systemd.
#include "core/control/sd_notify.h"

#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace ctl = crease::control;

namespace {

std::string receive(int fd) {
  char buf[512];
  const ssize_t n = ::recv(fd, buf, sizeof(buf), MSG_DONTWAIT);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

}  // namespace

TEST_CASE("notifications reach NOTIFY_SOCKET and are no-ops without it") {
  ::unsetenv("NOTIFY_SOCKET");
  CHECK_FALSE(ctl::notify_ready("x"));
  CHECK_FALSE(ctl::notify_watchdog());
  CHECK_FALSE(ctl::notify_stopping());

  const std::string path = "/tmp/crease_notify_" + std::to_string(::getpid()) + ".sock";
  ::unlink(path.c_str());
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM, 0);
  REQUIRE(fd >= 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof(addr.sun_path), "%s", path.c_str());
  REQUIRE(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0);
  ::setenv("NOTIFY_SOCKET", path.c_str(), 1);

  CHECK(ctl::notify_ready("3 loops running"));
  CHECK(receive(fd) == "READY=1\nSTATUS=3 loops running");
  CHECK(ctl::notify_watchdog());
  CHECK(receive(fd) == "WATCHDOG=1");
  CHECK(ctl::notify_status("cycle 1000"));
  CHECK(receive(fd) == "STATUS=cycle 1000");
  CHECK(ctl::notify_stopping());
  CHECK(receive(fd) == "STOPPING=1");

  ::unsetenv("NOTIFY_SOCKET");
  ::close(fd);
  ::unlink(path.c_str());
}

TEST_CASE("watchdog interval comes from WATCHDOG_USEC for this process") {
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("WATCHDOG_PID");
  CHECK_FALSE(ctl::watchdog_interval().has_value());
  ::setenv("WATCHDOG_USEC", "2000000", 1);
  ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  REQUIRE(ctl::watchdog_interval().has_value());
  CHECK(ctl::watchdog_interval()->count() == 2000000);
  ::setenv("WATCHDOG_PID", "1", 1);  // meant for another process
  CHECK_FALSE(ctl::watchdog_interval().has_value());
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("WATCHDOG_PID");
}
