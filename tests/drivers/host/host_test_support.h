// Shared by the host tests: a 1 kHz ticker on absolute deadlines and a unique bus name.
#pragma once

#include <pthread.h>
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <cstdint>
#include <string>

namespace crease::drivers::testing {

class Ticker {
 public:
  explicit Ticker(std::int64_t period_ns = 1'000'000) : period_(period_ns) { clock_gettime(CLOCK_MONOTONIC, &next_); }
  // Sleeps until the next period boundary; returns its time in ns.
  std::int64_t wait() {
    next_.tv_nsec += period_;
    while (next_.tv_nsec >= 1'000'000'000) {
      next_.tv_nsec -= 1'000'000'000;
      ++next_.tv_sec;
    }
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next_, nullptr);
    return std::int64_t{next_.tv_sec} * 1'000'000'000 + next_.tv_nsec;
  }

 private:
  std::int64_t period_;
  timespec next_{};
};

// Runs the calling thread (and the threads it creates meanwhile: brokers, device threads)
// under SCHED_FIFO where permitted, so a loaded shared machine does not starve the simulated
// devices' 1 ms deadlines. active() tells the test whether to expect near-perfect timing.
class ScopedFifo {
 public:
  explicit ScopedFifo(int priority = 60) {
    sched_param sp{};
    sp.sched_priority = priority;
    active_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
  }
  ~ScopedFifo() {
    sched_param sp{};
    if (active_) (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
  }
  ScopedFifo(const ScopedFifo&) = delete;
  ScopedFifo& operator=(const ScopedFifo&) = delete;
  [[nodiscard]] bool active() const noexcept { return active_; }

 private:
  bool active_ = false;
};

inline std::string unique_bus(const char* tag) {
  static int n = 0;
  return std::string(tag) + "-" + std::to_string(::getpid()) + "-" + std::to_string(++n);
}

}  // namespace crease::drivers::testing
