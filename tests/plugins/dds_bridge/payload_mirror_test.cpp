// The copies between port payloads and their IDL's C structs (hand_mirror.h,
// keypoints_mirror.h, arm_mirror.h, sheet_mirror.h, sheet_edit_mirror.h,
// world_shapes_mirror.h): a round trip keeps
// every field; the checks on the way in refuse non-finite and out-of-range values, inconsistent
// lengths and more entries than the payload holds.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "arm_mirror.h"
#include "hand_mirror.h"
#include "keypoints_mirror.h"
#include "sheet_edit_mirror.h"
#include "sheet_mirror.h"
#include "world_shapes_mirror.h"

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

TEST_CASE("arm_state and arm_command: a round trip keeps every field; bad values are refused") {
  ArmState s;
  s.timestamp_ns = 987654321;
  s.device_time_us = 17;
  s.valid = 0x5b;
  s.drive_state = 4;
  s.error_code = 0x2310;
  for (int j = 0; j < ArmState::kJoints; ++j) {
    s.position_rad[j] = 0.2f * j - 0.5f;
    s.velocity_rad_s[j] = -0.05f * j;
  }
  s.fresh = 1;
  s.health = DeviceHealth::ok;
  s.safe_state = 0;
  s.acked_seq = 65000;
  s.commands_sent = 1ull << 35;
  s.commands_failed = 9;
  Dds<ArmState>::C c{};
  Dds<ArmState>::Scratch scratch;
  Dds<ArmState>::to_dds(s, c, scratch);
  ArmState back;
  REQUIRE(Dds<ArmState>::from_dds(c, back) == SampleCheck::ok);
#define SAME_FIELD(f) CHECK(std::memcmp(&back.f, &s.f, sizeof(s.f)) == 0);
  CREASE_ARM_STATE_FIELDS(SAME_FIELD, SAME_FIELD)
#undef SAME_FIELD
  c.health = 3;
  CHECK(Dds<ArmState>::from_dds(c, back) == SampleCheck::malformed);
  c.health = 0;
  c.valid = 0x80;  // an eighth joint
  CHECK(Dds<ArmState>::from_dds(c, back) == SampleCheck::malformed);
  c.valid = 0x7f;
  c.velocity_rad_s[6] = -INFINITY;
  CHECK(Dds<ArmState>::from_dds(c, back) == SampleCheck::malformed);

  ArmCommand cmd;
  cmd.timestamp_ns = 12;
  cmd.mode = ArmCommand::velocity;
  cmd.position_rad[6] = -1.25f;
  cmd.velocity_rad_s[0] = 0.5f;
  Dds<ArmCommand>::C cc{};
  Dds<ArmCommand>::Scratch cs;
  Dds<ArmCommand>::to_dds(cmd, cc, cs);
  ArmCommand cmd_back;
  REQUIRE(Dds<ArmCommand>::from_dds(cc, cmd_back) == SampleCheck::ok);
#define SAME_FIELD(f) CHECK(std::memcmp(&cmd_back.f, &cmd.f, sizeof(cmd.f)) == 0);
  CREASE_ARM_COMMAND_FIELDS(SAME_FIELD, SAME_FIELD)
#undef SAME_FIELD
  cc.mode = 2;
  CHECK(Dds<ArmCommand>::from_dds(cc, cmd_back) == SampleCheck::malformed);
  cc.mode = 0;
  cc.position_rad[2] = NAN;
  CHECK(Dds<ArmCommand>::from_dds(cc, cmd_back) == SampleCheck::malformed);
}

TEST_CASE("sheet_state: only the valid nodes, creases and links travel; inconsistent or oversized samples are refused") {
  auto s = std::make_unique<SheetState>();
  s->timestamp_ns = 5;
  s->step = 77;
  s->nodes_u = 3;
  s->nodes_v = 2;
  s->width_mm = 210;
  s->height_mm = 297;
  s->link_count = 4;
  s->crease_count = 2;
  s->fit_error_mm = 0.75f;
  s->observations = 40;
  s->rollbacks = 1;
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 3; ++c) {
      s->position_mm[i][c] = 10.0f * i + c;
      s->normal[i][c] = c == 2 ? 1.0f : 0.0f;
    }
  for (int k = 0; k < 2; ++k) {
    for (int c = 0; c < 4; ++c) s->crease_mm[k][c] = 100.0f * k + c;
    s->crease_id[k] = 40 + k;
  }
  for (int l = 0; l < 4; ++l) s->strain[l] = 0.001f * l;
  s->strain[4] = NAN;  // beyond link_count: not carried, not checked
  auto c = std::make_unique<Dds<SheetState>::C>();
  Dds<SheetState>::Scratch scratch;
  Dds<SheetState>::to_dds(*s, *c, scratch);
  CHECK(c->position_mm._length == 18);
  CHECK(c->normal._length == 18);
  CHECK(c->crease_mm._length == 8);
  CHECK(c->crease_id._length == 2);
  CHECK(c->strain._length == 4);
  auto back = std::make_unique<SheetState>();
  REQUIRE(Dds<SheetState>::from_dds(*c, *back) == SampleCheck::ok);
#define SAME_FIELD(f) CHECK(std::memcmp(&back->f, &s->f, sizeof(s->f)) == 0);
  CREASE_SHEET_STATE_HEADER_FIELDS(SAME_FIELD, SAME_FIELD)
#undef SAME_FIELD
  CHECK(back->link_count == 4);
  CHECK(back->crease_count == 2);
  CHECK(std::memcmp(back->position_mm, s->position_mm, 6 * 3 * sizeof(float)) == 0);
  CHECK(std::memcmp(back->normal, s->normal, 6 * 3 * sizeof(float)) == 0);
  CHECK(std::memcmp(back->crease_mm, s->crease_mm, 2 * 4 * sizeof(float)) == 0);
  CHECK(back->crease_id[1] == 41);
  CHECK(std::memcmp(back->strain, s->strain, 4 * sizeof(float)) == 0);

  // Lengths that do not fit the grid or each other; a non-finite node; more than the payload holds.
  c->position_mm._length = 15;
  CHECK(Dds<SheetState>::from_dds(*c, *back) == SampleCheck::malformed);
  c->position_mm._length = 18;
  c->crease_mm._length = 4;
  CHECK(Dds<SheetState>::from_dds(*c, *back) == SampleCheck::malformed);
  c->crease_mm._length = 8;
  s->position_mm[5][1] = INFINITY;
  CHECK(Dds<SheetState>::from_dds(*c, *back) == SampleCheck::malformed);
  s->position_mm[5][1] = 0;
  c->strain._length = SheetState::kMaxLinks + 1;
  CHECK(Dds<SheetState>::from_dds(*c, *back) == SampleCheck::oversized);
  c->strain._length = 4;
  c->nodes_u = 65;
  c->nodes_v = 64;  // 4160 nodes: more than kMaxNodes
  CHECK(Dds<SheetState>::from_dds(*c, *back) == SampleCheck::oversized);
}

TEST_CASE("sheet_crease and sheet_memorize: a round trip keeps every field; bad events are refused") {
  SheetCreaseEvent e;
  e.timestamp_ns = 77;
  e.op = SheetCreaseEvent::Op::remove;
  e.id = 31;
  e.a_mm[1] = -4.5f;
  e.b_mm[0] = 210.0f;
  Dds<SheetCreaseEvent>::C c{};
  Dds<SheetCreaseEvent>::Scratch scratch;
  Dds<SheetCreaseEvent>::to_dds(e, c, scratch);
  SheetCreaseEvent back;
  REQUIRE(Dds<SheetCreaseEvent>::from_dds(c, back) == SampleCheck::ok);
#define SAME_FIELD(f) CHECK(std::memcmp(&back.f, &e.f, sizeof(e.f)) == 0);
  CREASE_SHEET_CREASE_EVENT_FIELDS(SAME_FIELD, SAME_FIELD)
#undef SAME_FIELD
  c.id = 32;  // ids are 0..31
  CHECK(Dds<SheetCreaseEvent>::from_dds(c, back) == SampleCheck::malformed);
  c.id = -1;
  CHECK(Dds<SheetCreaseEvent>::from_dds(c, back) == SampleCheck::malformed);
  c.op = 0;  // an add names no id
  CHECK(Dds<SheetCreaseEvent>::from_dds(c, back) == SampleCheck::ok);
  c.op = 3;
  CHECK(Dds<SheetCreaseEvent>::from_dds(c, back) == SampleCheck::malformed);
  c.op = 0;
  c.a_mm[0] = std::nanf("");
  CHECK(Dds<SheetCreaseEvent>::from_dds(c, back) == SampleCheck::malformed);
  c.a_mm[0] = 0;
  c.b_mm[1] = -INFINITY;
  CHECK(Dds<SheetCreaseEvent>::from_dds(c, back) == SampleCheck::malformed);

  SheetMemorizeEvent m;
  m.timestamp_ns = -3;
  m.whole_sheet = false;
  m.min_mm[0] = 1.0f;
  m.max_mm[1] = 297.0f;
  Dds<SheetMemorizeEvent>::C mc{};
  Dds<SheetMemorizeEvent>::Scratch ms;
  Dds<SheetMemorizeEvent>::to_dds(m, mc, ms);
  SheetMemorizeEvent mback;
  mback.whole_sheet = true;
  REQUIRE(Dds<SheetMemorizeEvent>::from_dds(mc, mback) == SampleCheck::ok);
#define SAME_FIELD(f) CHECK(std::memcmp(&mback.f, &m.f, sizeof(m.f)) == 0);
  CREASE_SHEET_MEMORIZE_EVENT_FIELDS(SAME_FIELD, SAME_FIELD)
#undef SAME_FIELD
  const std::uint8_t two = 2;  // a byte that is no bool
  std::memcpy(&mc.whole_sheet, &two, 1);
  CHECK(Dds<SheetMemorizeEvent>::from_dds(mc, mback) == SampleCheck::malformed);
  mc.whole_sheet = true;
  mc.max_mm[0] = INFINITY;
  CHECK(Dds<SheetMemorizeEvent>::from_dds(mc, mback) == SampleCheck::malformed);
}

TEST_CASE(
    "world_shapes: only `count` shapes travel, every field kept; out-of-range and oversized "
    "samples are refused") {
  auto w = std::make_unique<WorldShapes>();
  w->timestamp_ns = 123;
  w->step = 456;
  w->count = 3;
  w->reserved = 9;  // does not travel
  for (std::uint32_t i = 0; i < 3; ++i) {
    WorldShapes::Shape& s = w->shapes[i];
    s.kind = static_cast<WorldShapes::Kind>(i + 1);
    s.role = static_cast<WorldShapes::Role>(2 * i);
    s.side = static_cast<std::uint8_t>(i % 2);
    s.radius_mm = 8.5f + i;
    s.half_length_mm = 12.0f;
    s.half_mm[0] = 1.0f;
    s.half_mm[1] = 2.0f;
    s.half_mm[2] = 3.0f;
    s.position_mm[0] = 100.0f * i;
    s.position_mm[2] = -5.0f;
    s.rotation[1] = 0.5f;  // any 9 numbers travel as they are
  }
  auto c = std::make_unique<Dds<WorldShapes>::C>();
  auto scratch = std::make_unique<Dds<WorldShapes>::Scratch>();
  Dds<WorldShapes>::to_dds(*w, *c, *scratch);
  CHECK(c->shapes._length == 3);
  CHECK(c->shapes._buffer == scratch->shapes);
  CHECK(c->step == 456);
  auto back = std::make_unique<WorldShapes>();
  back->reserved = 7;
  REQUIRE(Dds<WorldShapes>::from_dds(*c, *back) == SampleCheck::ok);
  CHECK(back->timestamp_ns == 123);
  CHECK(back->step == 456);
  CHECK(back->count == 3);
  CHECK(back->reserved == 0);
  CHECK(std::memcmp(back->shapes, w->shapes, 3 * sizeof(WorldShapes::Shape)) == 0);

  scratch->shapes[1].kind = 4;  // past box
  CHECK(Dds<WorldShapes>::from_dds(*c, *back) == SampleCheck::malformed);
  scratch->shapes[1].kind = 0;
  scratch->shapes[1].role = 7;  // past arm
  CHECK(Dds<WorldShapes>::from_dds(*c, *back) == SampleCheck::malformed);
  scratch->shapes[1].role = 0;
  scratch->shapes[1].side = 2;
  CHECK(Dds<WorldShapes>::from_dds(*c, *back) == SampleCheck::malformed);
  scratch->shapes[1].side = 0;
  scratch->shapes[2].rotation[4] = INFINITY;
  CHECK(Dds<WorldShapes>::from_dds(*c, *back) == SampleCheck::malformed);
  scratch->shapes[2].rotation[4] = 1.0f;
  REQUIRE(Dds<WorldShapes>::from_dds(*c, *back) == SampleCheck::ok);
  c->shapes._length = WorldShapes::kCapacity + 1;
  CHECK(Dds<WorldShapes>::from_dds(*c, *back) == SampleCheck::oversized);
}
