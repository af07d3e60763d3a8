#include "rt/log_queue.h"

#include <doctest/doctest.h>

#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rt/alloc_guard.h"

TEST_CASE("records are truncated, never overflow, and format with their values") {
  crease::rt::RtLogQueue q(4);
  const std::string long_text(500, 'x');
  CHECK(q.try_log(crease::rt::LogLevel::warn, "a-very-long-source-name-that-does-not-fit", long_text.c_str(), 1, 7, 8, 2));
  crease::rt::LogRecord r;
  REQUIRE(q.try_pop(r));
  CHECK(std::string(r.text).size() == sizeof(r.text) - 1);
  CHECK(std::string(r.source).size() == sizeof(r.source) - 1);
  CHECK(crease::rt::format_log_record(r).find(" 7 8") != std::string::npos);
}

TEST_CASE("pushing a record allocates nothing; a full queue drops and counts") {
  crease::rt::RtLogQueue q(4);
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark mark;
    for (int i = 0; i < 6; ++i) (void)q.try_log(crease::rt::LogLevel::info, "src", "hello", i, i);
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(q.dropped() == 2);
}

TEST_CASE("the drain formats records from another thread") {
  std::mutex mu;
  std::vector<std::string> lines;
  crease::rt::RtLogQueue q(1024);
  {
    crease::rt::LogDrain drain(
        [&](const crease::rt::LogRecord& r) {
          std::lock_guard lock(mu);
          lines.push_back(crease::rt::format_log_record(r));
        },
        1);
    drain.add(&q);
    std::thread producer([&] {
      for (int i = 0; i < 500; ++i) {
        while (!q.try_log(crease::rt::LogLevel::info, "loop", "tick", i, i)) std::this_thread::yield();
      }
    });
    producer.join();
  }  // the drain's destructor drains what is left
  REQUIRE(lines.size() == 500);
  CHECK(lines.back() == "loop: tick 499");
}
