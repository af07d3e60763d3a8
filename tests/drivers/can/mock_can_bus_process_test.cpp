// The mock bus across processes (forks, so not under ThreadSanitizer).
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mock_bus_test_support.h"

using namespace crease::drivers;
using namespace crease::drivers::testing;

TEST_CASE("nodes in separate processes share a bus") {
  const std::string name = unique_bus("xproc");
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    // Echo server: answers every frame with id + 1. Retries until the broker exists.
    for (int attempt = 0; attempt < 500; ++attempt) {
      try {
        MockCanBus bus(node(name, 7));
        RxFrame rx;
        int echoed = 0;
        while (echoed < 100 && recv_wait(bus, rx, 2000) == RecvResult::frame) {
          CanFrame out = rx.frame;
          out.can_id = rx.frame.id() + 1;
          while (bus.send(out) != SendResult::ok) ::usleep(100);
          ++echoed;
        }
        ::_exit(echoed == 100 ? 0 : 3);
      } catch (...) {
        ::usleep(2000);
      }
    }
    ::_exit(2);
  }
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a(node(name, 1));
  REQUIRE(wait_nodes(broker, 2));
  int good = 0;
  for (std::uint32_t i = 0; i < 100; ++i) {
    REQUIRE(a.send(frame_with_id(0x200 + 2 * i)) == SendResult::ok);
    RxFrame rx;
    REQUIRE(recv_wait(a, rx) == RecvResult::frame);
    if (rx.frame.id() == 0x201 + 2 * i && rx.frame.data[1] == 0xA5) ++good;
  }
  CHECK(good == 100);
  int status = 0;
  ::waitpid(child, &status, 0);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
}

