#include "rt/histogram.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

using crease::rt::Histogram;

TEST_CASE("bucket bounds cover every value exactly once, within 1/32 relative width") {
  for (std::uint64_t v : {0ull, 1ull, 63ull, 64ull, 65ull, 127ull, 128ull, 1000ull, 999'999ull, 1ull << 39}) {
    const std::size_t b = Histogram::bucket_of(v);
    CHECK(Histogram::bucket_lower(b) <= v);
    CHECK(v <= Histogram::bucket_upper(b));
    if (v >= 64) CHECK(double(Histogram::bucket_upper(b) - Histogram::bucket_lower(b) + 1) <= double(v) / 32.0 + 1.0);
  }
  for (std::size_t b = 0; b + 1 < Histogram::kBuckets; ++b) {
    CHECK(Histogram::bucket_upper(b) + 1 == Histogram::bucket_lower(b + 1));
  }
}

TEST_CASE("percentiles equal a reference computed from the sorted samples") {
  std::mt19937_64 rng(42);
  std::lognormal_distribution<double> dist(10.0, 1.5);  // ~22 us median, long tail
  Histogram h;
  std::vector<std::uint64_t> samples;
  for (int i = 0; i < 100'000; ++i) {
    const auto v = static_cast<std::uint64_t>(dist(rng));
    samples.push_back(v);
    h.record(v, static_cast<std::uint64_t>(i), i);
  }
  std::sort(samples.begin(), samples.end());
  const auto snap = h.snapshot();
  CHECK(snap.count == samples.size());
  CHECK(snap.max_ns == samples.back());
  CHECK(snap.min_ns == samples.front());
  for (double p : {50.0, 90.0, 99.0, 99.9, 99.99, 100.0}) {
    const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * double(samples.size())));
    const std::uint64_t ref = samples[rank - 1];
    const std::uint64_t expect = std::min(Histogram::bucket_upper(Histogram::bucket_of(ref)), samples.back());
    CAPTURE(p);
    CHECK(snap.percentile(p) == expect);
  }
  // The worst samples, largest first, with their cycles.
  REQUIRE(snap.worst.size() == Histogram::kWorst);
  for (std::size_t i = 0; i < Histogram::kWorst; ++i) CHECK(snap.worst[i].value_ns == samples[samples.size() - 1 - i]);
}

TEST_CASE("empty histogram reports zeros; overflow is counted") {
  Histogram h;
  CHECK(h.snapshot().percentile(99) == 0);
  h.record(std::uint64_t{1} << 50, 1, 1);
  const auto s = h.snapshot();
  CHECK(s.overflow == 1);
  CHECK(s.count == 1);
}

TEST_CASE("stress: a reader snapshots while the writer records") {
  Histogram h;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t i = 0; i < 500'000; ++i) h.record(i % 10'000, i, static_cast<std::int64_t>(i));
    done = true;
  });
  std::uint64_t last = 0;
  while (!done) {
    const auto s = h.snapshot();
    CHECK(s.count >= last);
    last = s.count;
    if (s.count > 0) CHECK(s.percentile(100) <= 10'000);
  }
  writer.join();
  CHECK(h.snapshot().count == 500'000);
}
