#include "rt/histogram.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace crease::rt {

std::size_t Histogram::bucket_of(std::uint64_t v) noexcept {
  if (v < kLinear) return static_cast<std::size_t>(v);
  const int e = std::bit_width(v) - 1;  // >= 6
  if (e > kMaxExponent) return kBuckets - 1;
  const int shift = e - kSubBits;
  const std::uint64_t mantissa = (v >> shift) & ((1u << kSubBits) - 1);
  return kLinear + static_cast<std::size_t>(e - 6) * (1u << kSubBits) + mantissa;
}

std::uint64_t Histogram::bucket_lower(std::size_t b) noexcept {
  if (b < kLinear) return b;
  const std::size_t k = b - kLinear;
  const int e = static_cast<int>(k >> kSubBits) + 6;
  const std::uint64_t m = k & ((1u << kSubBits) - 1);
  return ((std::uint64_t{1} << kSubBits) + m) << (e - kSubBits);
}

std::uint64_t Histogram::bucket_upper(std::size_t b) noexcept {
  if (b < kLinear) return b;
  const int e = static_cast<int>((b - kLinear) >> kSubBits) + 6;
  return bucket_lower(b) + (std::uint64_t{1} << (e - kSubBits)) - 1;
}

void Histogram::record(std::uint64_t v, std::uint64_t cycle, std::int64_t time_ns) noexcept {
  const std::size_t b = bucket_of(v);
  if (b == kBuckets - 1 && v > bucket_upper(kBuckets - 1)) bump(overflow_, 1);
  bump(counts_[b], 1);
  const std::uint64_t n = count_.load(std::memory_order_relaxed);
  if (n == 0 || v < min_.load(std::memory_order_relaxed)) min_.store(v, std::memory_order_relaxed);
  if (v > max_.load(std::memory_order_relaxed)) max_.store(v, std::memory_order_relaxed);
  bump(sum_, v);
  count_.store(n + 1, std::memory_order_release);
  if (n < kWorst || v > worst_floor_) note_worst(v, cycle, time_ns);
}

void Histogram::note_worst(std::uint64_t v, std::uint64_t cycle, std::int64_t time_ns) noexcept {
  // Replace the smallest entry (empty entries have value 0 and cycle 0).
  std::size_t victim = 0;
  for (std::size_t i = 1; i < kWorst; ++i) {
    if (worst_value_[i].load(std::memory_order_relaxed) < worst_value_[victim].load(std::memory_order_relaxed)) victim = i;
  }
  const std::uint64_t s = worst_seq_.load(std::memory_order_relaxed);
  // A small seqlock; release stores / acquire loads instead of fences (see rt/latest.cpp).
  worst_seq_.store(s + 1, std::memory_order_relaxed);
  worst_value_[victim].store(v, std::memory_order_release);
  worst_cycle_[victim].store(cycle, std::memory_order_release);
  worst_time_[victim].store(time_ns, std::memory_order_release);
  worst_seq_.store(s + 2, std::memory_order_release);
  std::uint64_t floor = worst_value_[0].load(std::memory_order_relaxed);
  for (std::size_t i = 1; i < kWorst; ++i) floor = std::min(floor, worst_value_[i].load(std::memory_order_relaxed));
  worst_floor_ = floor;
}

void Histogram::reset() noexcept {
  for (auto& c : counts_) c.store(0, std::memory_order_relaxed);
  for (std::size_t i = 0; i < kWorst; ++i) {
    worst_value_[i].store(0, std::memory_order_relaxed);
    worst_cycle_[i].store(0, std::memory_order_relaxed);
    worst_time_[i].store(0, std::memory_order_relaxed);
  }
  count_.store(0, std::memory_order_relaxed);
  sum_.store(0, std::memory_order_relaxed);
  min_.store(0, std::memory_order_relaxed);
  max_.store(0, std::memory_order_relaxed);
  overflow_.store(0, std::memory_order_relaxed);
  worst_floor_ = 0;
}

HistogramSnapshot Histogram::snapshot() const {
  HistogramSnapshot s;
  s.counts.resize(kBuckets);
  // The total is recomputed from the buckets read, so percentiles stay self-consistent
  // while the writer keeps recording.
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < kBuckets; ++i) {
    s.counts[i] = counts_[i].load(std::memory_order_relaxed);
    total += s.counts[i];
  }
  s.count = total;
  s.sum_ns = sum_.load(std::memory_order_relaxed);
  s.min_ns = min_.load(std::memory_order_relaxed);
  s.max_ns = max_.load(std::memory_order_relaxed);
  s.overflow = overflow_.load(std::memory_order_relaxed);
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::uint64_t before = worst_seq_.load(std::memory_order_acquire);
    if (before & 1) continue;
    std::vector<Outlier> w;
    for (std::size_t i = 0; i < kWorst; ++i) {
      Outlier o{worst_value_[i].load(std::memory_order_acquire), worst_cycle_[i].load(std::memory_order_acquire),
                worst_time_[i].load(std::memory_order_acquire)};
      if (o.value_ns != 0 || o.time_ns != 0) w.push_back(o);
    }
    if (worst_seq_.load(std::memory_order_relaxed) != before) continue;
    std::sort(w.begin(), w.end(), [](const Outlier& a, const Outlier& b) { return a.value_ns > b.value_ns; });
    s.worst = std::move(w);
    break;
  }
  return s;
}

std::uint64_t HistogramSnapshot::percentile(double p) const noexcept {
  if (count == 0) return 0;
  const double clamped = std::clamp(p, 0.0, 100.0);
  auto rank = static_cast<std::uint64_t>(std::ceil(clamped / 100.0 * static_cast<double>(count)));
  rank = std::clamp<std::uint64_t>(rank, 1, count);
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < counts.size(); ++b) {
    seen += counts[b];
    if (seen >= rank) return std::min(Histogram::bucket_upper(b), max_ns);
  }
  return max_ns;
}

}  // namespace crease::rt
