// Monotonic time in nanoseconds, and the one sleep an RT loop may make.
#pragma once

#include <cerrno>
#include <cstdint>
#include <ctime>

namespace crease::rt {

inline constexpr std::int64_t kNsPerS = 1'000'000'000;

// CLOCK_MONOTONIC now, in ns. RT-safe (vDSO, no syscall on x86-64).
[[nodiscard]] inline std::int64_t now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * kNsPerS + ts.tv_nsec;
}

[[nodiscard]] inline timespec to_timespec(std::int64_t ns) noexcept {
  return timespec{static_cast<time_t>(ns / kNsPerS), static_cast<long>(ns % kNsPerS)};
}

// Sleeps until the absolute CLOCK_MONOTONIC deadline (ns), retrying on EINTR.
// clock_nanosleep(TIMER_ABSTIME), as cyclictest does: no drift, no relative-sleep slack.
inline void sleep_until_ns(std::int64_t deadline_ns) noexcept {
  const timespec ts = to_timespec(deadline_ns);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace crease::rt
