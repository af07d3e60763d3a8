// FrameSetWorker: each published set is processed on the worker thread and its result taken by
// the RT side once (a take when nothing new arrived says none, over many polls); an exception
// stops the worker, says failed with the reason and releases the reader end; a second worker
// on the same channel (a hot swap) waits for the reader end and takes over when the first stops.
// Threads: run under ThreadSanitizer too (label concurrency). No timing thresholds: the waits
// are bounded in count only.
#include "core/frames/frame_set_worker.h"

#include <doctest/doctest.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <thread>

using crease::frames::CameraSpec;
using crease::frames::FrameChannel;
using crease::frames::FrameSet;
using crease::frames::FrameSetWorker;
using namespace std::chrono_literals;

namespace {

struct Result {
  std::int64_t stamp_ns = 0;
  std::uint8_t first_pixel = 0;
  std::uint64_t frame = 0;
};

std::shared_ptr<FrameChannel> channel() {
  auto ch = std::make_shared<FrameChannel>("t", std::vector<CameraSpec>{{"cam0", 8, 4}});
  REQUIRE(ch->try_claim_writer());
  return ch;
}

void publish(FrameChannel& ch, std::uint8_t value, std::int64_t stamp, std::uint64_t frame) {
  std::memset(ch.write_slot().pixels(0), value, ch.image_bytes(0));
  ch.publish(stamp, frame, 0x1);
}

// Polls take_rt (as an RT update would, every 1 ms) until PRED(result) or 20000 polls.
template <class Pred>
bool take_until(FrameSetWorker& w, Result& r, Pred pred) {
  for (int i = 0; i < 20000; ++i) {
    if (w.take_rt(&r) == FrameSetWorker::Take::fresh && pred(r)) return true;
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

// A worker whose process copies the set's first pixel, or throws on a pixel of 0xEE.
struct Copier {
  explicit Copier(std::shared_ptr<FrameChannel> ch) : worker(std::move(ch), sizeof(Result)) {
    worker.start(
        [this](const FrameSet& s) {
          if (s.pixels(0)[0] == 0xEE) throw std::runtime_error("bad frame");
          out.stamp_ns = s.stamp_ns;
          out.first_pixel = s.pixels(0)[0];
          out.frame = s.frame;
        },
        &out);
  }
  Result out;  // worker thread
  FrameSetWorker worker;
};

}  // namespace

TEST_CASE("each published set is processed and taken once; nothing new arrived says none") {
  auto ch = channel();
  Copier c(ch);
  Result r;
  CHECK(c.worker.take_rt(&r) == FrameSetWorker::Take::none);  // nothing published
  for (std::uint8_t v = 1; v <= 20; ++v) {
    publish(*ch, v, 1000 * v, v);
    REQUIRE(take_until(c.worker, r, [&](const Result& x) { return x.frame == v; }));
    CHECK(r.first_pixel == v);
    CHECK(r.stamp_ns == 1000 * v);
    // Held: polls with nothing new published take nothing, and leave `r` as it was.
    for (int i = 0; i < 50; ++i) CHECK(c.worker.take_rt(&r) == FrameSetWorker::Take::none);
    CHECK(r.frame == v);
  }
  CHECK(c.worker.sets_processed() >= 20);  // at least one per set we waited for
  CHECK(c.worker.error().empty());
}

TEST_CASE("an exception stops the worker: failed, the reason, and the reader end released") {
  auto ch = channel();
  Copier c(ch);
  publish(*ch, 0xEE, 1, 1);
  FrameSetWorker::Take t = FrameSetWorker::Take::none;
  Result r;
  for (int i = 0; i < 20000 && t != FrameSetWorker::Take::failed; ++i) {
    t = c.worker.take_rt(&r);
    if (t != FrameSetWorker::Take::failed) std::this_thread::sleep_for(1ms);
  }
  REQUIRE(t == FrameSetWorker::Take::failed);
  CHECK(c.worker.error() == "bad frame");
  CHECK(ch->try_claim_reader());  // released: a successor (or a lockstep source) is not held up
  ch->release_reader();
  c.worker.stop();
  c.worker.stop();  // idempotent
}

TEST_CASE("a second worker on the channel waits for the reader end and takes over (a hot swap)") {
  auto ch = channel();
  auto first = std::make_unique<Copier>(ch);
  publish(*ch, 5, 5, 5);
  Result r;
  REQUIRE(take_until(first->worker, r, [](const Result& x) { return x.frame == 5; }));

  Copier second(ch);  // the reader end is held: it waits on its thread
  publish(*ch, 6, 6, 6);
  REQUIRE(take_until(first->worker, r, [](const Result& x) { return x.frame == 6; }));
  CHECK(second.worker.take_rt(&r) == FrameSetWorker::Take::none);

  first.reset();  // releases the reader end with a wake
  Result r2;
  // The second claims it and processes what is published from then on.
  bool took = false;
  for (std::uint8_t v = 7; v < 100 && !took; ++v) {
    publish(*ch, v, v, v);
    for (int i = 0; i < 200 && !took; ++i) {
      took = second.worker.take_rt(&r2) == FrameSetWorker::Take::fresh;
      if (!took) std::this_thread::sleep_for(1ms);
    }
  }
  REQUIRE(took);
  CHECK(r2.frame >= 7);
  CHECK(r2.first_pixel == r2.frame);
}
