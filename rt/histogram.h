// Log-linear histogram of durations in ns, written by one RT thread, read by any thread.
//
// Buckets: values below 64 ns have a bucket each; above, every power of two is split into 32
// equal sub-buckets, so a bucket's width is at most 1/32 (3.1 %) of its value. Values up to
// 2^40 ns (18 min) are kept; larger ones land in the last bucket and are counted as overflow.
// record() is wait-free (relaxed stores: one writer). The worst kWorst samples are kept with
// their cycle number and time, behind a small seqlock so a reader sees a consistent list.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace crease::rt {

struct Outlier {
  std::uint64_t value_ns = 0;
  std::uint64_t cycle = 0;   // the loop's cycle number when it happened
  std::int64_t time_ns = 0;  // CLOCK_MONOTONIC time when it happened
};

// A non-RT copy of a histogram, for percentiles and reports.
struct HistogramSnapshot {
  std::vector<std::uint64_t> counts;  // per bucket
  std::uint64_t count = 0;
  std::uint64_t sum_ns = 0;
  std::uint64_t min_ns = 0;  // 0 when empty
  std::uint64_t max_ns = 0;
  std::uint64_t overflow = 0;
  std::vector<Outlier> worst;  // largest first

  // Value at percentile p (0 < p <= 100): the upper bound of the bucket holding the sample of
  // rank ceil(p/100 * count), clamped to max_ns. 0 when empty.
  [[nodiscard]] std::uint64_t percentile(double p) const noexcept;
  [[nodiscard]] double mean_ns() const noexcept { return count ? double(sum_ns) / double(count) : 0.0; }
};

class Histogram {
 public:
  static constexpr int kSubBits = 5;                   // 32 sub-buckets per power of two
  static constexpr std::uint64_t kLinear = 64;         // exact buckets below this
  static constexpr int kMaxExponent = 40;              // 2^40 ns
  static constexpr std::size_t kBuckets = kLinear + (kMaxExponent - 6 + 1) * (1u << kSubBits);
  static constexpr std::size_t kWorst = 8;

  Histogram() = default;
  Histogram(const Histogram&) = delete;
  Histogram& operator=(const Histogram&) = delete;

  // One writer. Wait-free, RT-safe.
  void record(std::uint64_t value_ns, std::uint64_t cycle, std::int64_t time_ns) noexcept;
  // Any thread (not concurrently with record(): call it from the writer or when stopped).
  void reset() noexcept;
  // Any thread.
  [[nodiscard]] HistogramSnapshot snapshot() const;
  [[nodiscard]] std::uint64_t count() const noexcept { return count_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t max_ns() const noexcept { return max_.load(std::memory_order_relaxed); }

  [[nodiscard]] static std::size_t bucket_of(std::uint64_t value_ns) noexcept;
  [[nodiscard]] static std::uint64_t bucket_lower(std::size_t bucket) noexcept;
  [[nodiscard]] static std::uint64_t bucket_upper(std::size_t bucket) noexcept;  // inclusive

 private:
  static void bump(std::atomic<std::uint64_t>& a, std::uint64_t by) noexcept {
    a.store(a.load(std::memory_order_relaxed) + by, std::memory_order_relaxed);
  }
  void note_worst(std::uint64_t value_ns, std::uint64_t cycle, std::int64_t time_ns) noexcept;

  std::array<std::atomic<std::uint64_t>, kBuckets> counts_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::uint64_t> sum_{0};
  std::atomic<std::uint64_t> min_{0};
  std::atomic<std::uint64_t> max_{0};
  std::atomic<std::uint64_t> overflow_{0};
  // Worst samples, smallest kept value first-found by linear scan (kWorst is tiny).
  std::atomic<std::uint64_t> worst_seq_{0};
  std::array<std::atomic<std::uint64_t>, kWorst> worst_value_{};
  std::array<std::atomic<std::uint64_t>, kWorst> worst_cycle_{};
  std::array<std::atomic<std::int64_t>, kWorst> worst_time_{};
  std::uint64_t worst_floor_ = 0;  // writer-only: smallest value in the list once it is full
};

}  // namespace crease::rt
