#include "drivers/can/recording_can_bus.h"

#include <doctest/doctest.h>
#include <poll.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "rt/alloc_guard.h"
#include "rt/clock.h"

using namespace crease::drivers;

TEST_CASE("a recorded exchange reads back in order, and recording does not allocate") {
  const std::string name = "rec-" + std::to_string(::getpid());
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a_raw({name, 1, 0, 0}), b({name, 2, 0, 0});
  for (int i = 0; i < 500 && broker.connected_nodes() < 2; ++i) ::usleep(2000);
  RecordingCanBus a(a_raw, "can3");
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark mark;
    for (std::uint8_t i = 0; i < 50; ++i) {
      const std::uint8_t d[2] = {i, 0x42};
      REQUIRE(a.send(CanFrame::classic(0x100 + i, d)) == SendResult::ok);
      const CanFrame batch[2] = {CanFrame::fd(0x300, d), CanFrame::classic(0x301, d)};
      SendResult last;
      REQUIRE(a.send_batch(batch, &last) == 2);
    }
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  // Answers from b are recorded as received.
  RxFrame rx;
  int echoed = 0;
  while (echoed < 150) {
    if (b.try_receive(rx) == RecvResult::frame) {
      REQUIRE(b.send(rx.frame) == SendResult::ok);
      ++echoed;
    } else {
      pollfd p{b.fd(), POLLIN, 0};
      REQUIRE(::poll(&p, 1, 1000) == 1);
    }
  }
  int got = 0;
  for (int spins = 0; got < 150 && spins < 5000; ++spins) {
    if (a.try_receive(rx) == RecvResult::frame) ++got;
    else ::usleep(200);
  }
  CHECK(got == 150);
  const std::string path = "/tmp/crease_rec_" + std::to_string(::getpid()) + ".log";
  {
    CandumpWriter w(path);
    CHECK(a.drain_to(w) == 300);
  }
  CHECK(a.dropped() == 0);
  CandumpReader r(path);
  CandumpEntry e;
  int lines = 0, fd_frames = 0;
  while (r.next(e)) {
    CHECK(std::string(e.interface) == "can3");
    if (lines == 0) CHECK(e.frame.id() == 0x100);
    fd_frames += e.frame.is_fd() ? 1 : 0;
    ++lines;
  }
  CHECK(lines == 300);
  CHECK(fd_frames == 100);  // 50 sent + 50 echoed
  std::remove(path.c_str());
}

TEST_CASE("a full ring drops and counts instead of blocking") {
  const std::string name = "rec2-" + std::to_string(::getpid());
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus a_raw({name, 1, 0, 0});
  RecordingCanBus a(a_raw, "can0", 8);
  for (int i = 0; i < 20; ++i) REQUIRE(a.send(CanFrame::classic(0x10, {})) == SendResult::ok);
  CHECK(a.dropped() == 13);  // capacity 8 holds 7
}

namespace {
std::int64_t wall_ns() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec;
}
}  // namespace

TEST_CASE("a recording is stamped in wall-clock epoch time, as candump -L, with the monotonic intervals") {
  const std::string name = "rec3-" + std::to_string(::getpid());
  MockCanBroker broker({name, 0, 0, false});
  MockCanBus raw({name, 1, 0, 0});
  const std::int64_t wall_before = wall_ns();
  RecordingCanBus a(raw, "can0");
  std::int64_t mono[3];
  for (int i = 0; i < 3; ++i) {
    REQUIRE(a.send(CanFrame::classic(0x100 + static_cast<std::uint32_t>(i), {})) == SendResult::ok);
    mono[i] = crease::rt::now_ns();  // just after the record's stamp
    ::usleep(3000);
  }
  const std::int64_t wall_after = wall_ns();
  const std::string path = "/tmp/crease_rec3_" + std::to_string(::getpid()) + ".log";
  {
    CandumpWriter w(path);
    REQUIRE(a.drain_to(w) == 3);
  }
  CandumpReader r(path);
  CandumpEntry e[3];
  for (auto& x : e) REQUIRE(r.next(x));
  // Wall clock: between the clock before and after (the log's microseconds round down). A
  // monotonic stamp (time since boot) is decades before wall_before.
  CHECK(e[0].timestamp_ns >= wall_before - 1000);
  CHECK(e[2].timestamp_ns <= wall_after);
  // The intervals are the monotonic ones: each stamp minus the offset is a monotonic time at
  // or before the read that followed the send (to the microsecond of the log).
  for (int i = 0; i < 3; ++i) {
    CHECK(e[i].timestamp_ns - a.epoch_offset_ns() <= mono[i]);
    if (i > 0) CHECK(e[i].timestamp_ns - a.epoch_offset_ns() > mono[i - 1] - 1000);
  }
  std::remove(path.c_str());
}
