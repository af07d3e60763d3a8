// Monotonic time for the simulated devices.
#pragma once

#include <time.h>

#include <cstdint>

namespace crease::drivers::sim {

inline std::int64_t now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace crease::drivers::sim
