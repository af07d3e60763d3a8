// Port payloads of the test plugins (shared with the tests that read them).
#pragma once

#include <cmath>
#include <cstdint>

namespace crease::test_plugins {

// A number with where it came from.
struct TestValue {
  static constexpr char kPortType[] = "crease.test.Value";
  static constexpr std::uint32_t kPortVersion = 1;
  double value = 0.0;
  std::uint64_t count = 0;    // updates of the writer so far (carried across hot-swaps)
  std::int32_t version = 0;   // the writer's library version (1 or 2 for the counters)
  [[nodiscard]] bool all_finite() const noexcept { return std::isfinite(value); }
};

}  // namespace crease::test_plugins
