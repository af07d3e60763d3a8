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

// How old a bridged value was where it was read (crease_test_payload_probe), in
// CLOCK_MONOTONIC ns: sent_ns (the payload's timestamp_ns, set when the source wrote its port),
// arrived_ns (the port's stamp: when the bridge took the sample from DDS), seen_ns (the probe's
// update that read it).
struct LatencySample {
  static constexpr char kPortType[] = "crease.test.LatencySample";
  static constexpr std::uint32_t kPortVersion = 1;
  enum Kind : std::uint32_t { hand_state = 0, keypoints = 1 };
  std::int64_t sent_ns = 0;
  std::int64_t arrived_ns = 0;
  std::int64_t seen_ns = 0;
  std::uint64_t sequence = 0;  // the source's cycle index
  std::uint32_t kind = hand_state;
  std::uint32_t count = 0;     // key-points carried (keypoints)
};

}  // namespace crease::test_plugins
