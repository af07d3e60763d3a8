#include "drivers/protocol/arm_protocol.h"

#include <doctest/doctest.h>

#include <cmath>

#include "drivers/protocol/cia402.h"

using namespace crease::drivers;

TEST_CASE("arm command and status round-trip with micro-radian resolution") {
  arm::Command c;
  c.seq = 1234;
  c.controlword = cia402::kCmdEnableOperation;
  c.mode = arm::kModeCyclicVelocity;
  for (int j = 0; j < arm::kJoints; ++j) {
    c.position_rad[j] = -3.0f + static_cast<float>(j);
    c.velocity_rad_s[j] = 0.25f * static_cast<float>(j);
  }
  arm::Command d;
  REQUIRE(arm::decode(10, arm::encode(10, c), d) == Decode::ok);
  CHECK(d.seq == 1234);
  CHECK(d.controlword == 0x000F);
  CHECK(d.mode == arm::kModeCyclicVelocity);
  for (int j = 0; j < arm::kJoints; ++j) {
    CHECK(std::abs(d.position_rad[j] - c.position_rad[j]) < 1e-5);
    CHECK(std::abs(d.velocity_rad_s[j] - c.velocity_rad_s[j]) < 1e-3);
  }
  arm::Status s;
  s.cmd_seq = 1234;
  s.statusword = cia402::statusword(cia402::State::operation_enabled);
  s.valid = 0x7F;
  s.mode = arm::kModeCyclicPosition;
  s.sync_counter = 200;
  s.nmt = canopen::NmtState::operational;
  s.position_rad[6] = 1.234567f;
  arm::Status sd;
  REQUIRE(arm::decode(10, arm::encode(10, s), sd) == Decode::ok);
  CHECK(cia402::state_from_statusword(sd.statusword) == cia402::State::operation_enabled);
  CHECK(sd.valid == 0x7F);
  CHECK(sd.sync_counter == 200);
  CHECK(std::abs(sd.position_rad[6] - 1.234567f) < 2e-6);
}

TEST_CASE("arm frames: corruption, wrong node, bad mode") {
  arm::Command c;
  CanFrame f = arm::encode(4, c);
  arm::Command d;
  CHECK(arm::decode(5, f, d) == Decode::not_mine);
  f.data[20] ^= 0x10;
  CHECK(arm::decode(4, f, d) == Decode::bad_crc);
  c.mode = 3;  // not a mode this protocol knows
  CHECK(arm::decode(4, arm::encode(4, c), d) == Decode::bad_format);
}
