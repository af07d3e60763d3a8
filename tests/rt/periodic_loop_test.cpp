#include "rt/periodic_loop.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "rt/alloc_guard.h"
#include "rt/clock.h"

namespace {
struct Recorder {
  std::atomic<std::uint64_t> runs{0};
  std::atomic<std::int64_t> busy_ns{0};
  std::atomic<std::uint64_t> busy_on_cycle{UINT64_MAX};  // the first cycle at or past it is long
  std::atomic<std::uint64_t> busy_cycle{UINT64_MAX};     // the cycle that was
  std::uint64_t cycles[4096] = {};
  std::atomic<bool> was_rt{true};
};
void body(void* ctx, const crease::rt::CycleClock& c) noexcept {
  auto* r = static_cast<Recorder*>(ctx);
  const auto n = r->runs.load(std::memory_order_relaxed);
  if (n < 4096) r->cycles[n] = c.cycle;
  if (!crease::rt::this_thread_is_rt()) r->was_rt = false;
  // At or past: a loaded machine may skip the deadline named (a late wake-up skips periods too).
  if (c.cycle >= r->busy_on_cycle.load() && r->busy_cycle.load() == UINT64_MAX) {
    r->busy_cycle.store(c.cycle);
    const auto until = crease::rt::now_ns() + r->busy_ns.load();
    while (crease::rt::now_ns() < until) {
    }
  }
  r->runs.store(n + 1, std::memory_order_release);
}
}  // namespace

TEST_CASE("a 1 kHz loop runs at its rate, on an RT-marked thread, and stops") {
  Recorder rec;
  crease::rt::PeriodicLoop loop({"t1k", 1'000'000, {}}, &body, &rec);
  const auto t0 = std::chrono::steady_clock::now();
  loop.start();
  // It runs (however loaded the machine: up to 10 s for 100 cycles) and never faster than its
  // rate: the mechanism, not the timing quality, which is crease-bench jitter's.
  for (int i = 0; i < 2000 && rec.runs.load() < 100; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  loop.stop();
  const auto elapsed_ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0).count();
  const auto runs = rec.runs.load();
  CHECK(runs >= 100);
  CHECK(runs <= elapsed_ms + 2);
  CHECK(rec.was_rt.load());
  CHECK(loop.timing().cycles.load() == runs);
  CHECK(loop.timing().wakeup_latency.count() == runs);
  CHECK(loop.timing().period.count() == runs - 1);
}

namespace {
struct Deadlines {
  std::atomic<std::uint64_t> runs{0};
  std::int64_t deadline[64] = {};
};
void record_deadline(void* ctx, const crease::rt::CycleClock& c) noexcept {
  auto* d = static_cast<Deadlines*>(ctx);
  const auto n = d->runs.load(std::memory_order_relaxed);
  if (n < 64) d->deadline[n] = c.deadline_ns;
  d->runs.store(n + 1, std::memory_order_release);
}
}  // namespace

TEST_CASE("deadlines lie on the period's grid, shifted by the phase: two loops of one rate keep it") {
  Deadlines a, b;
  crease::rt::PeriodicLoop::Settings sa{"grid0", 1'000'000, {}}, sb{"grid300", 1'000'000, {}};
  sb.phase_ns = 300'000;
  crease::rt::PeriodicLoop la(sa, &record_deadline, &a), lb(sb, &record_deadline, &b);
  la.start();
  lb.start();
  while (a.runs.load() < 20 || b.runs.load() < 20) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  la.stop();
  lb.stop();
  for (int i = 0; i < 20; ++i) {
    CHECK(a.deadline[i] % 1'000'000 == 0);
    CHECK(b.deadline[i] % 1'000'000 == 300'000);
  }
}

TEST_CASE("an overrun skips the missed periods instead of replaying them") {
  Recorder rec;
  rec.busy_on_cycle = 20;
  rec.busy_ns = 25'000'000;  // 25 periods of 1 ms
  crease::rt::PeriodicLoop loop({"skip", 1'000'000, {}}, &body, &rec);
  loop.start();
  while (rec.runs.load() < 40) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  loop.stop();
  const auto& t = loop.timing();
  CHECK(t.overruns.load() >= 1);
  CHECK(t.missed_periods.load() >= 24);
  // Late wake-ups are counted among the overruns, never beside them. (Whether the long
  // cycle's own overrun counts as late depends on when a loaded machine woke it.)
  CHECK(t.late_wakes.load() <= t.overruns.load());
  // The cycle after the long one is numbered past the skipped deadlines: no burst replays them.
  const std::uint64_t busy = rec.busy_cycle.load();
  std::size_t i = 0;
  while (i + 1 < std::min<std::uint64_t>(rec.runs.load(), 4096) && rec.cycles[i] != busy) ++i;
  REQUIRE(rec.cycles[i] == busy);
  CHECK(rec.cycles[i + 1] >= busy + 25);
  // Bodies after the overrun start no sooner than one period apart on average (no burst):
  // 10 bodies take at least ~9 periods.
  CHECK(t.execution.snapshot().max_ns >= 25'000'000);
}

TEST_CASE("settings that cannot be applied are reported, never fatal") {
  Recorder rec;
  crease::rt::PeriodicLoop::Settings s{"prio", 1'000'000, {}};
  s.thread.priority = 50;
  s.thread.cpu = 100000;  // no such CPU
  crease::rt::PeriodicLoop loop(s, &body, &rec);
  const auto steps = loop.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  loop.stop();
  bool saw_cpu = false;
  for (const auto& st : steps) {
    if (st.kind == crease::rt::SetupStep::Kind::affinity) {
      saw_cpu = true;
      CHECK(st.what.find("CPU affinity 100000 for loop 'prio'") != std::string::npos);
      CHECK_FALSE(st.applied);
      CHECK_FALSE(st.why.empty());
    }
    if (st.kind == crease::rt::SetupStep::Kind::sched_fifo) {
      CHECK(st.what.find("SCHED_FIFO priority 50") != std::string::npos);
      CHECK(st.applied == loop.fifo_applied());
    }
  }
  CHECK(saw_cpu);
  CHECK(rec.runs.load() > 0);
}
