#include "rt/latest.h"

#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

namespace {
// A payload whose every word repeats the same number: a torn read shows as a mismatch.
struct Block {
  std::uint64_t words[32];  // 256 bytes
};
Block block_of(std::uint64_t n) {
  Block b;
  for (auto& w : b.words) w = n;
  return b;
}
bool consistent(const Block& b) {
  for (auto w : b.words) {
    if (w != b.words[0]) return false;
  }
  return true;
}
}  // namespace

TEST_CASE("a reader sees no data, then new data, then old data") {
  crease::rt::LatestChannel ch(sizeof(Block));
  crease::rt::LatestWriter<Block> w(&ch);
  crease::rt::LatestReader<Block> r(&ch);
  CHECK(r.poll().flow == crease::rt::Flow::no_data);
  CHECK(!r.has_value());
  CHECK(r.value().words[0] == 0);  // value-initialised before the first write
  w.write(block_of(7), 1234);
  auto info = r.poll();
  CHECK(info.flow == crease::rt::Flow::new_data);
  CHECK(info.seq == 1);
  CHECK(info.stamp_ns == 1234);
  CHECK(r.value().words[31] == 7);
  info = r.poll();
  CHECK(info.flow == crease::rt::Flow::old_data);
  CHECK(info.seq == 1);
  CHECK(info.stamp_ns == 1234);
  w.write(block_of(8), 1235);
  w.write(block_of(9), 1236);
  info = r.poll();
  CHECK(info.is_new());
  CHECK(info.seq == 3);
  CHECK(r.value().words[0] == 9);
}

// The trap this API closes: a value read once must still be the value on the cycles after it,
// when nothing new arrived (a command written once is the command until the next one).
TEST_CASE("the value is held across many polls with nothing new, and replaced only by a new one") {
  crease::rt::LatestChannel ch(sizeof(Block));
  crease::rt::LatestWriter<Block> w(&ch);
  crease::rt::LatestReader<Block> r(&ch);
  w.write(block_of(42), 1);
  REQUIRE(r.poll().is_new());
  int changed = 0, old = 0;
  for (int cycle = 0; cycle < 1000; ++cycle) {
    const auto info = r.poll();
    old += info.flow == crease::rt::Flow::old_data ? 1 : 0;
    changed += (r.value().words[0] != 42 || !consistent(r.value())) ? 1 : 0;
  }
  CHECK(old == 1000);
  CHECK(changed == 0);
  CHECK(r.held().seq == 1);
  w.write(block_of(43), 2);
  CHECK(r.poll().is_new());
  CHECK(r.value().words[5] == 43);
}

TEST_CASE("odd payload sizes are copied exactly") {
  struct Odd {
    char c[13];
  };
  crease::rt::LatestChannel ch(sizeof(Odd));
  Odd in{};
  for (int i = 0; i < 13; ++i) in.c[i] = static_cast<char>('a' + i);
  ch.write(&in, 1);
  unsigned char out[16];
  std::memset(out, 0xEE, sizeof(out));
  ch.read(out, 0);
  CHECK(std::memcmp(out, in.c, 13) == 0);
  CHECK(out[13] == 0xEE);  // nothing written past the payload
}

// The writer writes every ~2 us (2000 times the 1 kHz control rate); readers copy and check.
TEST_CASE("stress: one writer, two readers, never a torn or backwards value") {
  crease::rt::LatestChannel ch(sizeof(Block));
  std::atomic<bool> done{false};
  constexpr std::uint64_t kWrites = 100'000;
  auto reader = [&] {
    crease::rt::LatestReader<Block> r(&ch);
    std::uint64_t last = 0, torn = 0, backwards = 0, reads = 0;
    while (!done.load(std::memory_order_acquire)) {
      const auto info = r.poll();
      const Block& b = r.value();
      if (!consistent(b)) ++torn;  // also on old data: a torn retry never reaches value()
      if (!info.is_new()) continue;
      ++reads;
      if (b.words[0] < last) ++backwards;
      if (b.words[0] != info.seq) ++torn;  // value n was written as the n-th write
      last = b.words[0];
    }
    CHECK(torn == 0);
    CHECK(backwards == 0);
    CHECK(reads > 0);
  };
  std::thread r1(reader), r2(reader);
  crease::rt::LatestWriter<Block> w(&ch);
  for (std::uint64_t i = 1; i <= kWrites; ++i) {
    w.write(block_of(i), static_cast<std::int64_t>(i));
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(2);
    while (std::chrono::steady_clock::now() < until) {
    }
  }
  done.store(true, std::memory_order_release);
  r1.join();
  r2.join();
  CHECK(ch.sequence() == kWrites);
}
