#include "drivers/can/can_frame.h"

#include <doctest/doctest.h>
#include <linux/can/error.h>

#include <cstring>

#include "drivers/can/can_bus.h"

using namespace crease::drivers;

TEST_CASE("CanFrame has the byte layout of struct can_frame / canfd_frame") {
  const std::uint8_t bytes[3] = {1, 2, 3};
  CanFrame f = CanFrame::classic(0x123, bytes);
  can_frame k{};
  std::memcpy(&k, &f, sizeof(k));
  CHECK(k.can_id == 0x123);
  CHECK(k.can_dlc == 3);
  CHECK(k.data[2] == 3);
  CHECK(f.mtu() == CAN_MTU);
  CHECK_FALSE(f.is_fd());

  const std::uint8_t big[10] = {9, 9, 9, 9, 9, 9, 9, 9, 9, 9};
  CanFrame g = CanFrame::fd(0x456 | CAN_EFF_FLAG, big);
  CHECK(g.is_fd());
  CHECK(g.len == 12);  // rounded up to a valid FD length
  CHECK(g.data[10] == 0);
  CHECK(g.id() == 0x456);
  CHECK(g.mtu() == CANFD_MTU);
  canfd_frame kf{};
  std::memcpy(&kf, &g, sizeof(kf));
  CHECK(kf.len == 12);
  CHECK((kf.flags & CANFD_BRS) != 0);
}

TEST_CASE("FD lengths and DLC codes") {
  CHECK(can_fd_round_len(9) == 12);
  CHECK(can_fd_round_len(33) == 48);
  CHECK(can_fd_round_len(64) == 64);
  CHECK(can_fd_valid_len(24));
  CHECK_FALSE(can_fd_valid_len(25));
  for (std::uint8_t d = 0; d < 16; ++d) CHECK(can_len_to_dlc(can_dlc_to_len(d)) == d);
}

TEST_CASE("frame wire time scales with bitrate and payload") {
  const std::uint8_t b8[8] = {};
  const CanFrame c = CanFrame::classic(0x100, b8);
  // 8-byte classic frame: ~111 bits nominal, up to ~135 with stuffing.
  const auto bits = can_frame_bits(c).nominal_bits;
  CHECK(bits >= 111);
  CHECK(bits <= 135);
  CHECK(can_frame_time_ns(c, 1'000'000, 0) == std::int64_t{bits} * 1000);
  CHECK(can_frame_time_ns(c, 500'000, 0) == 2 * can_frame_time_ns(c, 1'000'000, 0));
  std::uint8_t b64[64] = {};
  const CanFrame f = CanFrame::fd(0x100, b64);
  // 64 bytes in one FD frame (data phase at 5 Mbit/s) beat eight 8-byte classic frames by 5x,
  // and a 64-byte FD frame at 1/5 Mbit/s takes 120..180 us.
  const auto fd_ns = can_frame_time_ns(f, 1'000'000, 5'000'000);
  CHECK(fd_ns * 5 < 8 * can_frame_time_ns(c, 1'000'000, 0));
  CHECK(fd_ns > 120'000);
  CHECK(fd_ns < 180'000);
}

TEST_CASE("error frames move the bus state") {
  BusState s = BusState::error_active;
  s = bus_state_after_error_frame(s, make_error_frame_for_state(BusState::error_warning));
  CHECK(s == BusState::error_warning);
  s = bus_state_after_error_frame(s, make_error_frame_for_state(BusState::error_passive));
  CHECK(s == BusState::error_passive);
  s = bus_state_after_error_frame(s, make_error_frame_for_state(BusState::bus_off));
  CHECK(s == BusState::bus_off);
  CanFrame prot;
  prot.can_id = CAN_ERR_FLAG | CAN_ERR_PROT;
  prot.len = CAN_ERR_DLC;
  CHECK(bus_state_after_error_frame(s, prot) == BusState::bus_off);  // held until restart
  s = bus_state_after_error_frame(s, make_error_frame_for_state(BusState::error_active));
  CHECK(s == BusState::error_active);
}
