// What a hook is charged against its time budget: its wall time less the time its thread was
// preempted, all of it when the thread blocked.
#include "rt/thread_cpu.h"

#include <doctest/doctest.h>

#include "rt/clock.h"

using crease::rt::charged_hook_ns;
using crease::rt::ThreadCpuSample;

TEST_CASE("a hook never preempted is charged its wall time") {
  const ThreadCpuSample start{0, 0, 5};
  const ThreadCpuSample now{1'000'000, 1'000'000, 5};  // 1 ms on the CPU in 1 ms
  CHECK(charged_hook_ns(800'000, start, now) == 800'000);
}

TEST_CASE("the time the thread was off the CPU is not charged, at most the whole hook") {
  const ThreadCpuSample start{0, 0, 5};
  const ThreadCpuSample now{4'000'000, 1'000'000, 5};  // 3 ms preempted in the cycle
  CHECK(charged_hook_ns(3'500'000, start, now) == 500'000);
  CHECK(charged_hook_ns(2'000'000, start, now) == 0);  // never negative
}

TEST_CASE("a thread that blocked in the cycle is charged the whole wall time") {
  const ThreadCpuSample start{0, 0, 5};
  const ThreadCpuSample now{4'000'000, 1'000'000, 6};  // one voluntary switch: a sleep, a lock
  CHECK(charged_hook_ns(3'500'000, start, now) == 3'500'000);
}

TEST_CASE("a sample that failed gives no discount") {
  const ThreadCpuSample start{0, -1, -1};
  const ThreadCpuSample now{4'000'000, 1'000'000, 5};
  CHECK(charged_hook_ns(3'500'000, start, now) == 3'500'000);
}

TEST_CASE("the samples follow the thread: spinning adds CPU time, sleeping adds a voluntary switch") {
  const ThreadCpuSample a = crease::rt::sample_thread_cpu();
  ThreadCpuSample b = a;
  while (b.cpu_ns - a.cpu_ns < 5'000'000) b = crease::rt::sample_thread_cpu();  // 5 ms of CPU
  CHECK(b.wall_ns - a.wall_ns >= b.cpu_ns - a.cpu_ns - 100'000);  // no more CPU than wall time (0.1 ms: the reads' order)
  crease::rt::sleep_until_ns(crease::rt::now_ns() + 2'000'000);
  const ThreadCpuSample c = crease::rt::sample_thread_cpu();
  CHECK(c.voluntary > b.voluntary);
  CHECK(c.wall_ns - b.wall_ns >= 2'000'000);
}
