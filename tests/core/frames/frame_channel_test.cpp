// Frame channel: newest-set hand-over, sets overwritten unread counted, one writer / one
// reader, no allocation on publish or acquire, and configuration errors that name the channel.
// (Binding channels by name, as ports of kind frames: tests/core/port_registry_test.cpp.)
#include "core/frames/frame_channel.h"

#include <doctest/doctest.h>

#include <cstring>

#include "core/errors.h"
#include "rt/alloc_guard.h"

using crease::frames::CameraSpec;
using crease::frames::FrameChannel;
using crease::frames::FrameSet;

namespace {
std::vector<CameraSpec> two_cams() {
  return {{"cam0", 8, 4}, {"cam1", 6, 3}};
}

void fill(FrameChannel& ch, std::uint8_t value) {
  for (std::size_t k = 0; k < ch.cameras().size(); ++k)
    std::memset(ch.write_slot().pixels(k), value, ch.image_bytes(k));
}
}  // namespace

TEST_CASE("the reader gets the newest published set, once, with what the writer said") {
  FrameChannel ch("t", two_cams());
  CHECK(ch.all_cameras_mask() == 0x3u);
  REQUIRE(ch.try_claim_writer());
  REQUIRE(ch.try_claim_reader());
  CHECK(ch.acquire_newest() == nullptr);

  fill(ch, 7);
  CHECK(ch.publish(100, 10, 0x3) == 1);
  fill(ch, 8);
  CHECK(ch.publish(200, 11, 0x1 | 0x10) == 2);  // bits beyond the cameras are dropped
  CHECK(ch.published() == 2);

  const FrameSet* s = ch.acquire_newest();
  REQUIRE(s != nullptr);
  CHECK(s->sequence == 2);
  CHECK(s->frame == 11);
  CHECK(s->stamp_ns == 200);
  CHECK(s->valid_mask == 0x1u);
  CHECK(s->valid(0));
  CHECK_FALSE(s->valid(1));
  CHECK(s->pixels(0)[0] == 8);
  CHECK(s->pixels(1)[6 * 3 - 1] == 8);
  CHECK(ch.consumed() == 2);
  CHECK(ch.finished() == 0);
  ch.finish(s->sequence);
  CHECK(ch.finished() == 2);
  CHECK(ch.acquire_newest() == nullptr);  // nothing newer

  // The writer never touches the set the reader holds.
  fill(ch, 9);
  ch.publish(300, 12, 0x3);
  fill(ch, 10);
  CHECK(s->pixels(0)[0] == 8);
  ch.publish(400, 13, 0x3);
  CHECK(s->pixels(0)[0] == 8);
  s = ch.acquire_newest();
  REQUIRE(s != nullptr);
  CHECK(s->frame == 13);
  CHECK(s->pixels(1)[0] == 10);
}

TEST_CASE("a set replaced before the reader took it is counted as overwritten") {
  FrameChannel ch("t", two_cams());
  CHECK(ch.set_bytes() == 8 * 4 + 6 * 3);
  REQUIRE(ch.try_claim_writer());
  REQUIRE(ch.try_claim_reader());
  ch.publish(1, 1, 0x3);
  CHECK(ch.overwritten() == 0);
  ch.publish(2, 2, 0x3);  // set 1 was never acquired
  CHECK(ch.overwritten() == 1);
  REQUIRE(ch.acquire_newest() != nullptr);
  ch.publish(3, 3, 0x3);  // set 2 was taken: nothing lost
  CHECK(ch.overwritten() == 1);
  ch.publish(4, 4, 0x3);
  ch.publish(5, 5, 0x3);
  CHECK(ch.overwritten() == 3);
  const FrameSet* s = ch.acquire_newest();
  REQUIRE(s != nullptr);
  CHECK(s->sequence == 5);
  CHECK(ch.published() == 5);
}

TEST_CASE("one writer and one reader at a time; releasing changes the signal") {
  FrameChannel ch("t", two_cams());
  REQUIRE(ch.try_claim_writer());
  CHECK_FALSE(ch.try_claim_writer());
  CHECK(ch.writer_claimed());
  const std::uint64_t s0 = ch.signal();
  ch.release_writer();
  CHECK(ch.signal() != s0);
  CHECK(ch.try_claim_writer());
  REQUIRE(ch.try_claim_reader());
  CHECK_FALSE(ch.try_claim_reader());
  ch.release_reader();
  CHECK_FALSE(ch.reader_claimed());
  CHECK(ch.try_claim_reader());
}

TEST_CASE("publish and acquire allocate nothing") {
  FrameChannel ch("t", two_cams());
  REQUIRE(ch.try_claim_writer());
  REQUIRE(ch.try_claim_reader());
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark mark;
    for (int i = 0; i < 100; ++i) {
      fill(ch, static_cast<std::uint8_t>(i));
      ch.publish(i, static_cast<std::uint64_t>(i), 0x3);
      if (i % 3 == 0) CHECK(ch.acquire_newest() != nullptr);
    }
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  if (crease::rt::alloc_hooks_installed()) {  // the counter would have seen one
    crease::rt::ScopedRtMark mark;
    static char* volatile sink;
    sink = new char[8];
    CHECK(crease::rt::rt_allocation_count() > before);
    delete[] sink;
  }
}

TEST_CASE("bad rigs are configuration errors that name the channel and the camera") {
  CHECK_THROWS_WITH_AS(FrameChannel("empty", {}), doctest::Contains("'empty': no cameras"),
                       crease::ConfigError);
  CHECK_THROWS_WITH_AS(FrameChannel("z", {{"a", 0, 4}}), doctest::Contains("'a' has size 0x4"),
                       crease::ConfigError);
  CHECK_THROWS_WITH_AS(FrameChannel("d", {{"a", 2, 2}, {"a", 2, 2}}),
                       doctest::Contains("listed twice"), crease::ConfigError);
  std::vector<CameraSpec> many(33, CameraSpec{"", 1, 1});
  for (std::size_t k = 0; k < many.size(); ++k) many[k].name = "c" + std::to_string(k);
  CHECK_THROWS_WITH_AS(FrameChannel("m", many), doctest::Contains("at most 32"),
                       crease::ConfigError);
}
