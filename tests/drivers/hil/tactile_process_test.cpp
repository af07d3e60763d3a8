// The simulated tactile matrix as its own process on a pty; the host reads it through a
// Boost.Asio serial port.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "../host/host_test_support.h"
#include "drivers/host/tactile_host.h"

using namespace crease::drivers;

TEST_CASE("crease-simdevice tactile streams samples over its pty") {
  const std::string cmd = std::string(CREASE_BIN_DIR) + "/crease-simdevice tactile --force 1.5 --seconds 2";
  FILE* p = ::popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  char line[256] = {};
  REQUIRE(std::fgets(line, sizeof(line), p) != nullptr);
  std::string path(line);
  REQUIRE(path.rfind("pty: ", 0) == 0);
  path = path.substr(5);
  while (!path.empty() && (path.back() == '\n' || path.back() == '\r')) path.pop_back();
  {
    SerialPort port({path, 1'000'000, false});
    TactileHost host(port.fd(), {.rate_hz = 200});
    crease::drivers::testing::Ticker tick;
    std::int64_t now = 0;
    for (int i = 0; i < 3000 && (i < 300 || host.health(now) != LinkHealth::ok); ++i) host.read_from_rt(now = tick.wait());
    CHECK(host.health(now) == LinkHealth::ok);
    CHECK(host.samples() > 20);
    CHECK(host.sample().pressure_kpa[3][16] > 10.0f);  // 1.5 N: ~15 kPa at the centre taxel
    CHECK(host.link().rx_stats().crc_errors == 0);
  }
  ::pclose(p);  // the device stops after --seconds
}
