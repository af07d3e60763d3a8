#include "rt/periodic_loop.h"

#include <pthread.h>

#include <cstdlib>
#include <cstdio>

#include "rt/alloc_guard.h"
#include "rt/clock.h"

namespace crease::rt {

PeriodicLoop::PeriodicLoop(Settings settings, Body body, void* ctx)
    : settings_(std::move(settings)), body_(body), ctx_(ctx) {
  if (settings_.period_ns <= 0 || body_ == nullptr || settings_.phase_ns < 0 || settings_.phase_ns >= settings_.period_ns) {
    std::fprintf(stderr, "crease: PeriodicLoop '%s' needs a positive period, a phase in [0, period) and a body\n",
                 settings_.name.c_str());
    std::abort();
  }
}

PeriodicLoop::~PeriodicLoop() { stop(); }

std::vector<SetupStep> PeriodicLoop::start() {
  running_.store(true, std::memory_order_release);
  thread_ = std::thread([this] { run_thread(); });
  while (!setup_done_.load(std::memory_order_acquire)) std::this_thread::yield();
  return steps_;
}

void PeriodicLoop::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  running_.store(false, std::memory_order_release);
}

void PeriodicLoop::run_thread() {
  // Thread name for top/perf: at most 15 characters.
  const std::string short_name = ("crease-" + settings_.name).substr(0, 15);
  pthread_setname_np(pthread_self(), short_name.c_str());
  steps_ = apply_thread_settings(settings_.name, settings_.thread);
  fifo_.store(this_thread_is_fifo(), std::memory_order_relaxed);
  setup_done_.store(true, std::memory_order_release);

  mark_this_thread_rt(true);
  const std::int64_t period = settings_.period_ns;
  // The first grid point at least one period ahead.
  const std::int64_t earliest = now_ns() + period;
  std::int64_t deadline = earliest - (earliest - settings_.phase_ns) % period;
  if (deadline < earliest) deadline += period;
  timing_.started_ns.store(deadline, std::memory_order_relaxed);
  std::uint64_t cycle = 0;
  std::int64_t previous_wake = 0;
  std::uint64_t executed = 0, overruns = 0, missed = 0, late_wakes = 0;

  while (!stop_.load(std::memory_order_acquire)) {
    sleep_until_ns(deadline);
    const std::int64_t wake = now_ns();
    const CycleClock clock{cycle, deadline, wake, period};
    body_(ctx_, clock);
    const std::int64_t end = now_ns();

    timing_.wakeup_latency.record(static_cast<std::uint64_t>(wake - deadline), cycle, wake);
    timing_.execution.record(static_cast<std::uint64_t>(end - wake), cycle, wake);
    if (previous_wake != 0) timing_.period.record(static_cast<std::uint64_t>(wake - previous_wake), cycle, wake);
    previous_wake = wake;
    timing_.cycles.store(++executed, std::memory_order_relaxed);

    deadline += period;
    ++cycle;
    if (end >= deadline) {
      // Skip every deadline already past; never run a burst to catch up.
      if (wake >= deadline) timing_.late_wakes.store(++late_wakes, std::memory_order_relaxed);
      const std::int64_t skipped = (end - deadline) / period + 1;
      deadline += skipped * period;
      cycle += static_cast<std::uint64_t>(skipped);
      timing_.overruns.store(++overruns, std::memory_order_relaxed);
      missed += static_cast<std::uint64_t>(skipped);
      timing_.missed_periods.store(missed, std::memory_order_relaxed);
    }
  }
  mark_this_thread_rt(false);
}

}  // namespace crease::rt
