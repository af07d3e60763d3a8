#include "rt/queue.h"

#include <doctest/doctest.h>

#include <cstdint>
#include <thread>

TEST_CASE("capacity rounds up to a power of two; overflow is counted, not blocking") {
  crease::rt::QueueChannel q(sizeof(int), 5);
  CHECK(q.capacity() == 8);
  crease::rt::QueueWriter<int> w(&q);
  crease::rt::QueueReader<int> r(&q);
  for (int i = 0; i < 8; ++i) CHECK(w.try_push(i));
  CHECK_FALSE(w.try_push(99));
  CHECK(q.dropped() == 1);
  CHECK(q.pushed() == 8);
  int v = -1;
  for (int i = 0; i < 8; ++i) {
    REQUIRE(r.try_pop(v));
    CHECK(v == i);
  }
  CHECK_FALSE(r.try_pop(v));
  CHECK(w.try_push(100));  // room again after popping
  CHECK(q.size_approx() == 1);
}

TEST_CASE("stress: SPSC keeps every record, in order") {
  struct Rec {
    std::uint64_t n;
    std::uint64_t check;
  };
  crease::rt::QueueChannel q(sizeof(Rec), 64);
  constexpr std::uint64_t kCount = 300'000;
  std::thread producer([&] {
    crease::rt::QueueWriter<Rec> w(&q);
    for (std::uint64_t i = 0; i < kCount;) {
      if (w.try_push(Rec{i, ~i})) ++i;
    }
  });
  crease::rt::QueueReader<Rec> r(&q);
  std::uint64_t expected = 0, bad = 0;
  Rec rec{};
  while (expected < kCount) {
    if (!r.try_pop(rec)) continue;
    if (rec.n != expected || rec.check != ~expected) ++bad;
    ++expected;
  }
  producer.join();
  CHECK(bad == 0);
  CHECK(q.pushed() == kCount);
}
