#include "drivers/can/socket_can_bus.h"

#include <doctest/doctest.h>
#include <net/if.h>
#include <poll.h>

#include <cerrno>
#include <cstdio>
#include <system_error>

using namespace crease::drivers;

namespace {
// Returns true (and reports the test skipped, with the reason) when SocketCAN cannot be
// exercised here. ctest sees "SKIPPED: " (SKIP_REGULAR_EXPRESSION) and reports "Skipped".
bool skip_without_vcan() {
  std::string reason;
  if (!SocketCanBus::available(&reason)) {
    std::printf("SKIPPED: AF_CAN unavailable on this kernel (%s)\n", reason.c_str());
    MESSAGE("SKIPPED: " << reason);
    return true;
  }
  if (::if_nametoindex("vcan0") == 0) {
    std::printf("SKIPPED: AF_CAN present but no vcan0 interface (modprobe vcan; ip link add vcan0 type vcan)\n");
    MESSAGE("SKIPPED: no vcan0");
    return true;
  }
  return false;
}
}  // namespace

TEST_CASE("without AF_CAN the constructor fails with a clear error") {
  std::string reason;
  if (SocketCanBus::available(&reason)) return;  // covered by the vcan test below
  CHECK(reason.find("socket(PF_CAN") != std::string::npos);
  try {
    SocketCanBus bus({"vcan0", true, {}, false});
    FAIL("constructor must throw without AF_CAN");
  } catch (const std::system_error& e) {
    CHECK(e.code().value() == EAFNOSUPPORT);
    CHECK(std::string(e.what()).find("vcan0") != std::string::npos);
  }
}

TEST_CASE("classic and FD frames round-trip on vcan0 with filters and timestamps") {
  if (skip_without_vcan()) return;
  SocketCanBus tx({"vcan0", true, {}, false});
  SocketCanBus rx({"vcan0", true, {{0x120, 0x7F0}}, false});
  const std::uint8_t b[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  REQUIRE(tx.send(CanFrame::classic(0x300, b)) == SendResult::ok);  // filtered out
  REQUIRE(tx.send(CanFrame::classic(0x121, b)) == SendResult::ok);
  REQUIRE(tx.send(CanFrame::fd(0x122, b)) == SendResult::ok);
  RxFrame r;
  pollfd p{rx.fd(), POLLIN, 0};
  REQUIRE(::poll(&p, 1, 1000) == 1);
  REQUIRE(rx.try_receive(r) == RecvResult::frame);
  CHECK(r.frame.id() == 0x121);
  CHECK_FALSE(r.frame.is_fd());
  CHECK(r.timestamp_ns > 0);
  REQUIRE(::poll(&p, 1, 1000) == 1);
  REQUIRE(rx.try_receive(r) == RecvResult::frame);
  CHECK(r.frame.id() == 0x122);
  CHECK(r.frame.is_fd());
  CHECK(r.frame.len == 12);
  CHECK(rx.try_receive(r) == RecvResult::empty);
}

TEST_CASE("send_batch puts classic and FD frames on vcan0 in order with one sendmmsg") {
  if (skip_without_vcan()) return;
  SocketCanBus tx({"vcan0", true, {}, false});
  SocketCanBus rx({"vcan0", true, {{0x130, 0x7F0}}, false});
  const std::uint8_t b[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  const CanFrame frames[3] = {CanFrame::classic(0x131, b), CanFrame::fd(0x132, b), CanFrame::classic(0x133, b)};
  SendResult last = SendResult::error;
  REQUIRE(tx.send_batch(frames, &last) == 3);
  CHECK(last == SendResult::ok);
  CHECK(tx.counters().tx_frames == 3);
  pollfd p{rx.fd(), POLLIN, 0};
  for (const CanFrame& f : frames) {
    RxFrame r;
    REQUIRE(::poll(&p, 1, 1000) == 1);
    REQUIRE(rx.try_receive(r) == RecvResult::frame);
    CHECK(r.frame == f);
  }
}
