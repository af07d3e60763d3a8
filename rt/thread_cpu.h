// What the calling thread has run and been switched out for, to tell a hook's own time from the
// time the thread was preempted (the firewall's time budget, core/loop.cpp).
#pragma once

#include <cstdint>

namespace crease::rt {

struct ThreadCpuSample {
  std::int64_t wall_ns = 0;        // CLOCK_MONOTONIC when sampled
  std::int64_t cpu_ns = 0;         // the thread's CPU time (CLOCK_THREAD_CPUTIME_ID, exact to now)
  std::int64_t voluntary = 0;      // the thread's voluntary context switches so far (it blocked)
};

// Two system calls that never block (clock_gettime of the thread's CPU clock, and
// getrusage(RUSAGE_THREAD) for the switch count; about 0.5 us together). RT-safe. getrusage's own
// CPU times are not used: for the running thread they lag by up to a scheduler tick.
[[nodiscard]] ThreadCpuSample sample_thread_cpu() noexcept;

// The part of a hook's wall time `hook_ns` charged to the hook, given samples at the cycle's
// start and just after the hook. Preemption is not charged: the time the thread spent off the CPU
// in the cycle so far (a bound on the hook's share of it) is taken off, so the charge is a lower
// bound on the hook's CPU time. Blocking is charged in full: if the thread switched out
// voluntarily in the cycle (a sleep, a lock, blocking I/O) the whole wall time counts.
[[nodiscard]] std::int64_t charged_hook_ns(std::int64_t hook_ns, const ThreadCpuSample& cycle_start,
                                           const ThreadCpuSample& now) noexcept;

}  // namespace crease::rt
