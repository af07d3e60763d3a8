// A writer thread publishing as fast as it can against a reader thread acquiring: every set the
// reader gets is whole (each byte of every image carries the set's sequence), sequences only
// grow, and the last one arrives. Run under ThreadSanitizer (label concurrency).
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>

#include "core/frames/frame_channel.h"

using crease::frames::FrameChannel;

TEST_CASE("writer and reader threads: whole sets, increasing sequences, the newest arrives") {
  FrameChannel ch("stress", {{"a", 64, 32}, {"b", 17, 9}, {"c", 3, 5}});
  // The writer goes on until the reader took this many sets, or for at most 2 s (a loaded machine).
  constexpr std::uint64_t kWantAcquired = 500;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  std::atomic<std::uint64_t> got{0};
  std::uint64_t written = 0;
  REQUIRE(ch.try_claim_writer());  // claimed here, written on the thread below
  std::thread writer([&] {
    std::uint64_t i = 1;
    for (; got.load(std::memory_order_relaxed) < kWantAcquired &&
           std::chrono::steady_clock::now() < deadline;
         ++i) {
      for (std::size_t k = 0; k < ch.cameras().size(); ++k)
        std::memset(ch.write_slot().pixels(k), static_cast<int>(i & 0xff), ch.image_bytes(k));
      ch.publish(static_cast<std::int64_t>(i), i, static_cast<std::uint32_t>(i & 0x7));
    }
    written = i - 1;
    ch.release_writer();  // after the last publish: the reader stops once it has that set
  });

  REQUIRE(ch.try_claim_reader());
  std::uint64_t last = 0;
  bool torn = false;
  while (true) {
    const std::uint64_t seen = ch.signal();
    const auto* s = ch.acquire_newest();
    if (s == nullptr) {
      if (!ch.writer_claimed() && ch.published() == last) break;
      ch.wait_signal(seen);
      continue;
    }
    got.fetch_add(1, std::memory_order_relaxed);
    if (s->sequence <= last || s->frame != s->sequence ||
        s->stamp_ns != static_cast<std::int64_t>(s->sequence) ||
        s->valid_mask != (s->sequence & 0x7))
      torn = true;
    const auto want = static_cast<std::uint8_t>(s->sequence & 0xff);
    for (std::size_t k = 0; k < ch.cameras().size(); ++k)
      for (std::size_t b = 0; b < ch.image_bytes(k); ++b)
        if (s->pixels(k)[b] != want) torn = true;
    last = s->sequence;
    ch.finish(last);
  }
  writer.join();
  CHECK_FALSE(torn);
  CHECK(last == written);  // the newest set always arrives
  CHECK(got.load() > 10);  // many hand-overs while the writer was writing
  CHECK(ch.consumed() == written);
  CHECK(ch.finished() == written);
}
