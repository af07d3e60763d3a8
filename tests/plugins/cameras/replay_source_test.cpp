// ReplaySource: a recording made at any earlier time plays with the replay's time (the first
// frame stamped with the time of the first grab, the recorded intervals kept), never before a
// frame is due, decoded ahead on named non-RT threads into a bounded window, counting how far
// behind it is when its consumer comes late, and a wait for a far-off frame ends on cancel().
#include "plugins/cameras/replay_source.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "rt/clock.h"
#include "support/opencv_threads.h"
#include "rt/thread_placement.h"

using namespace crease::vision;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {
constexpr std::int64_t kS = 1'000'000'000;

// A recording of two tiny cameras, frame i stamped stamps[i] (ns), camera k's grey level 10 i + k.
std::string make_recording(const std::string& name, const std::vector<std::int64_t>& stamps) {
  const fs::path dir = fs::temp_directory_path() / ("crease_replay_source_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  for (int k = 0; k < 2; ++k) {
    fs::create_directories(dir / ("cam" + std::to_string(k)));
    save_camera(look_at_camera("c" + std::to_string(k), 64, 48, 60, {k * 100.0, -60, 450}, {0, 0, 0}),
                (dir / ("cam" + std::to_string(k) + ".yaml")).string());
  }
  std::ofstream csv(dir / "timestamps.csv");
  csv << "frame,timestamp_ns\n";
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    csv << i << "," << stamps[i] << "\n";
    for (int k = 0; k < 2; ++k)
      REQUIRE(cv::imwrite(replay_frame_path(dir.string(), static_cast<std::size_t>(k), i),
                          cv::Mat(48, 64, CV_8UC1, cv::Scalar(static_cast<double>(10 * i + static_cast<std::size_t>(k))))));
  }
  return dir.string();
}

// A thread of this process is named NAME, within 4 s (a decoder names itself when it first
// runs, which on a loaded machine may be after the others filled the queue).
bool thread_named(const std::string& name) {
  for (int i = 0; i < 2000; ++i) {
    for (const crease::rt::ThreadInfo& t : crease::rt::list_threads())
      if (t.name == name) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}
}  // namespace

TEST_CASE("a recording made 2000 s ago plays with fresh stamps, its intervals kept, none before its time") {
  crease::testing::own_threads_only();
  // Before this process, maybe before boot: 2000 s, or as long as the clock has run when the
  // machine booted less than that ago (recorded stamps are never negative).
  const std::int64_t now = crease::rt::now_ns();
  const std::int64_t ago = std::min<std::int64_t>(2000 * kS, now - 1);
  const std::int64_t then = now - ago;
  const std::vector<std::int64_t> recorded = {then, then + 66'000'000, then + 133'000'000, then + 200'000'000};
  ReplaySource src(make_recording("old", recorded));
  REQUIRE(src.frames() == 4);
  CHECK(src.start_ns() == 0);  // not started before the first grab
  // All four decoded first, so that only this thread's own scheduling can make a frame late.
  for (int i = 0; i < 2000 && src.queued() < 4; ++i) std::this_thread::sleep_for(2ms);
  CHECK(src.start_ns() == 0);
  const std::int64_t before = crease::rt::now_ns();
  Frame f;
  std::vector<std::int64_t> stamps;
  for (int i = 0; i < 4; ++i) {
    REQUIRE(src.grab(f));
    const std::int64_t delivered = crease::rt::now_ns();
    CAPTURE(i);
    CHECK(f.index == static_cast<std::uint64_t>(i));
    CHECK(f.timestamp_ns <= delivered);  // never handed out before it is due
    stamps.push_back(f.timestamp_ns);
    REQUIRE(f.images.size() == 2);
    CHECK(f.images[1].at<unsigned char>(0, 0) == 10 * i + 1);
  }
  CHECK_FALSE(src.grab(f));  // the end
  const std::int64_t after = crease::rt::now_ns();
  // The first frame at the replay's start (the first grab), not at its recorded time...
  CHECK(stamps[0] == src.start_ns());
  CHECK(stamps[0] >= before);
  CHECK(stamps[3] <= after);
  CHECK(stamps[0] - recorded[0] >= ago);  // the recorded stamps would be that old
  // ...and every frame its recorded interval after it; a frame handed out late (this thread
  // preempted past its successor's time on a loaded machine) moves the start, so the rest keep
  // their intervals from it, never closer than recorded.
  for (std::size_t i = 1; i < 4; ++i) {
    CAPTURE(i);
    if (src.late() == 0) {
      CHECK(stamps[i] - stamps[0] == recorded[i] - recorded[0]);
    } else {
      CHECK(stamps[i] - stamps[i - 1] >= recorded[i] - recorded[i - 1]);
    }
  }
  if (src.late() != 0) MESSAGE(src.late() << " of 4 frames handed out late (a loaded machine)");
  CHECK(src.played() == 4);
}

TEST_CASE("frames are decoded ahead on crease-replay threads, at most read_ahead of them, handed out in order") {
  ReplaySource src(make_recording("ahead", {0, 1, 2, 3, 4, 5, 6, 7}), 2, 3);
  // The decoder runs without a grab, named, until the queue is full...
  bool full = false;
  for (int i = 0; i < 2000 && !full; ++i) {
    full = src.queued() == 2;
    if (!full) std::this_thread::sleep_for(2ms);
  }
  REQUIRE(full);
  CHECK(thread_named("crease-replay-0"));
  CHECK(thread_named("crease-replay-2"));
  std::this_thread::sleep_for(50ms);
  CHECK(src.queued() == 2);  // ...and no further: bounded
  Frame f;
  for (int i = 0; i < 8; ++i) {
    REQUIRE(src.grab(f));
    CHECK(f.index == static_cast<std::uint64_t>(i));  // in order, whichever thread decoded it
    CHECK(f.images[0].at<unsigned char>(0, 0) == 10 * i);
    CHECK(src.queued() <= 2);
  }
  CHECK_FALSE(src.grab(f));
}

TEST_CASE("a consumer that comes late: late frames counted, the lag too, and the replay plays slower with fresh stamps") {
  // Frames 1 ms apart; the consumer takes one every >= 30 ms.
  ReplaySource src(make_recording("late", {0, 1'000'000, 2'000'000, 3'000'000}));
  for (int i = 0; i < 2000 && src.queued() < 4; ++i) std::this_thread::sleep_for(2ms);
  REQUIRE(src.queued() == 4);  // decoded: what follows is the consumer's lateness alone
  Frame f;
  REQUIRE(src.grab(f));
  CHECK(src.late() == 0);  // the first frame is due when it is handed out
  CHECK(src.last_lag_ns() == 0);
  std::int64_t previous = f.timestamp_ns;
  for (int i = 1; i < 4; ++i) {
    std::this_thread::sleep_for(30ms);
    const std::int64_t asked = crease::rt::now_ns();
    REQUIRE(src.grab(f));
    CAPTURE(i);
    // Late: stamped when handed out, not 29 ms in the past; never closer than recorded.
    CHECK(f.timestamp_ns >= asked);
    CHECK(f.timestamp_ns <= crease::rt::now_ns());
    CHECK(f.timestamp_ns - previous >= 1'000'000);
    previous = f.timestamp_ns;
  }
  CHECK(src.played() == 4);
  CHECK(src.late() == 3);
  CHECK(src.last_lag_ns() >= 90'000'000 - 3'000'000);  // 3 x 30 ms of sleeps for 3 ms of recording
  CHECK(src.max_lag_ns() == src.last_lag_ns());
  CHECK(src.start_ns() == f.timestamp_ns - 3'000'000);  // the start moved with every late frame
}

TEST_CASE("a grab waiting for a frame due in 1000 s returns false on cancel()") {
  ReplaySource src(make_recording("gap", {0, 1000 * kS}));
  Frame f;
  REQUIRE(src.grab(f));
  std::thread canceller([&] {
    std::this_thread::sleep_for(50ms);
    src.cancel();
  });
  CHECK_FALSE(src.grab(f));
  canceller.join();
  CHECK(src.played() == 1);
  CHECK_FALSE(src.grab(f));
}
