// The copies between port payloads and their IDL's C structs (hand_mirror.h,
// keypoints_mirror.h): a round trip keeps every field; the checks on the way in refuse
// non-finite and out-of-range values and more key-points than the payload holds.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "hand_mirror.h"
#include "keypoints_mirror.h"

using namespace crease;
using crease::dds_bridge::Dds;
using crease::dds_bridge::SampleCheck;

TEST_CASE("hand_state and hand_command: a round trip keeps every field; bad values are refused") {
  HandState s;
  s.timestamp_ns = 123456789;
  s.device_time_us = 42;
  s.valid = 0xabcde;
  for (int j = 0; j < HandState::kJoints; ++j) s.position_rad[j] = 0.1f * j;
  for (int k = 0; k < HandState::kPressureSensors; ++k) s.pressure_kpa[k] = 100.0f + k;
  s.pressure_valid = 0x1f;
  s.fresh = 1;
  s.health = DeviceHealth::degraded;
  s.safe_state = 0;
  s.acked_seq = 777;
  s.commands_sent = 1ull << 40;
  s.commands_failed = 3;
  Dds<HandState>::C c{};
  Dds<HandState>::Scratch scratch;
  Dds<HandState>::to_dds(s, c, scratch);
  HandState back;
  REQUIRE(Dds<HandState>::from_dds(c, back) == SampleCheck::ok);
#define SAME_FIELD(f) CHECK(std::memcmp(&back.f, &s.f, sizeof(s.f)) == 0);
  CREASE_HAND_STATE_FIELDS(SAME_FIELD, SAME_FIELD)
#undef SAME_FIELD
  c.health = 3;
  CHECK(Dds<HandState>::from_dds(c, back) == SampleCheck::malformed);
  c.health = 0;
  c.pressure_kpa[2] = INFINITY;
  CHECK(Dds<HandState>::from_dds(c, back) == SampleCheck::malformed);

  HandCommand cmd;
  cmd.timestamp_ns = -5;
  cmd.target_rad[19] = 1.5f;
  cmd.stiffness_nm_per_rad[0] = 2.0f;
  cmd.enable = 1;
  Dds<HandCommand>::C cc{};
  Dds<HandCommand>::Scratch cs;
  Dds<HandCommand>::to_dds(cmd, cc, cs);
  HandCommand cmd_back;
  REQUIRE(Dds<HandCommand>::from_dds(cc, cmd_back) == SampleCheck::ok);
  CHECK(cmd_back.target_rad[19] == 1.5f);
  CHECK(cmd_back.stiffness_nm_per_rad[0] == 2.0f);
  CHECK(cmd_back.timestamp_ns == -5);
  CHECK(cmd_back.enable == 1);
  cc.target_rad[4] = NAN;
  CHECK(Dds<HandCommand>::from_dds(cc, cmd_back) == SampleCheck::malformed);
}

TEST_CASE("keypoints: only `count` points travel; out-of-range and oversized samples are refused") {
  auto k = std::make_unique<Keypoints>();
  k->timestamp_ns = 99;
  k->frame = 7;
  k->cameras_ok = 0x1f;
  k->count = 3;
  for (std::uint32_t i = 0; i < 3; ++i) k->points[i] = Keypoint{{1.0f * i, 2, 3}, {4, 5}, 0.25f, 11, 4, 1, 0x5};
  auto c = std::make_unique<Dds<Keypoints>::C>();
  auto scratch = std::make_unique<Dds<Keypoints>::Scratch>();
  Dds<Keypoints>::to_dds(*k, *c, *scratch);
  CHECK(c->points._length == 3);
  CHECK(c->points._buffer == scratch->points);
  auto back = std::make_unique<Keypoints>();
  REQUIRE(Dds<Keypoints>::from_dds(*c, *back) == SampleCheck::ok);
  CHECK(back->count == 3);
  CHECK(back->frame == 7);
  CHECK(back->cameras_ok == 0x1f);
  CHECK(std::memcmp(back->points, k->points, 3 * sizeof(Keypoint)) == 0);

  scratch->points[1].corner = 5;
  CHECK(Dds<Keypoints>::from_dds(*c, *back) == SampleCheck::malformed);
  scratch->points[1].corner = 0;
  scratch->points[1].face = 2;
  CHECK(Dds<Keypoints>::from_dds(*c, *back) == SampleCheck::malformed);
  scratch->points[1].face = 0;
  scratch->points[2].reproj_error_px = NAN;
  CHECK(Dds<Keypoints>::from_dds(*c, *back) == SampleCheck::malformed);
  c->points._length = Keypoints::kCapacity + 1;
  CHECK(Dds<Keypoints>::from_dds(*c, *back) == SampleCheck::oversized);
}
