#include "drivers/protocol/hand_protocol.h"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>

using namespace crease::drivers;

TEST_CASE("hand command, stiffness, status and pressure round-trip within one unit") {
  hand::Command c;
  c.seq = 0xBEEF;
  c.flags = hand::kCmdEnable;
  for (int j = 0; j < hand::kJoints; ++j) c.target_rad[j] = -1.5f + 0.15f * static_cast<float>(j);
  const CanFrame f = hand::encode(3, c);
  CHECK(f.is_fd());
  CHECK(f.id() == 0x203);
  CHECK(f.len == hand::kCommandLen);
  hand::Command d;
  REQUIRE(hand::decode(3, f, d) == Decode::ok);
  CHECK(d.seq == 0xBEEF);
  CHECK(d.flags == hand::kCmdEnable);
  for (int j = 0; j < hand::kJoints; ++j) CHECK(std::abs(d.target_rad[j] - c.target_rad[j]) <= 0.5e-4 + 1e-6);

  hand::Stiffness s;
  s.seq = 7;
  for (int j = 0; j < hand::kJoints; ++j) s.stiffness_nm_per_rad[j] = 0.5f * static_cast<float>(j);
  hand::Stiffness sd;
  REQUIRE(hand::decode(3, hand::encode(3, s), sd) == Decode::ok);
  CHECK(sd.stiffness_nm_per_rad[19] == doctest::Approx(9.5).epsilon(1e-3));

  hand::Status st;
  st.cmd_seq = 41;
  st.stiff_seq = 7;
  st.nmt = canopen::NmtState::operational;
  st.flags = hand::kStatusEnabled;
  st.sync_counter = 17;
  st.device_time_us = 0x12345678;
  st.valid = 0xFFFFF;
  for (int j = 0; j < hand::kJoints; ++j) st.position_rad[j] = 0.01f * static_cast<float>(j);
  hand::Status sdd;
  REQUIRE(hand::decode(3, hand::encode(3, st), sdd) == Decode::ok);
  CHECK(sdd.cmd_seq == 41);
  CHECK(sdd.sync_counter == 17);
  CHECK(sdd.device_time_us == 0x12345678u);
  CHECK(sdd.valid == 0xFFFFFu);
  CHECK(sdd.nmt == canopen::NmtState::operational);
  CHECK(sdd.position_rad[10] == doctest::Approx(0.1).epsilon(1e-3));

  hand::Pressure p;
  p.valid = 0x1F;
  p.pressure_kpa[4] = 101.3f;
  hand::Pressure pd;
  REQUIRE(hand::decode(3, hand::encode(3, p), pd) == Decode::ok);
  CHECK(pd.pressure_kpa[4] == doctest::Approx(101.3).epsilon(1e-4));
}

TEST_CASE("every single-bit corruption of a command is caught by the CRC") {
  hand::Command c;
  c.seq = 99;
  for (int j = 0; j < hand::kJoints; ++j) c.target_rad[j] = 0.3f;
  const CanFrame f = hand::encode(1, c);
  hand::Command d;
  for (int bit = 0; bit < 8 * f.len; ++bit) {
    CanFrame g = f;
    g.data[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    CHECK(hand::decode(1, g, d) == Decode::bad_crc);
  }
}

TEST_CASE("foreign, short, classic frames and out-of-range values") {
  hand::Command c;
  const CanFrame f = hand::encode(1, c);
  hand::Command d;
  CHECK(hand::decode(2, f, d) == Decode::not_mine);
  CanFrame shortf = f;
  shortf.len = 32;
  CHECK(hand::decode(1, shortf, d) == Decode::bad_format);
  CanFrame classic = CanFrame::classic(f.can_id, {f.data, 8});
  CHECK(hand::decode(1, classic, d) == Decode::bad_format);
  hand::Status st;
  CHECK(hand::decode(1, f, st) == Decode::not_mine);  // a command is not a status

  c.target_rad[0] = 100.0f;  // saturates at +3.2767 rad
  c.target_rad[1] = std::numeric_limits<float>::quiet_NaN();  // NaN encodes as 0
  c.target_rad[2] = -100.0f;
  REQUIRE(hand::decode(1, hand::encode(1, c), d) == Decode::ok);
  CHECK(d.target_rad[0] == doctest::Approx(3.2767));
  CHECK(d.target_rad[1] == 0.0f);
  CHECK(d.target_rad[2] == doctest::Approx(-3.2768));
}
