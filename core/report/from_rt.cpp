#include "core/report/from_rt.h"

namespace crease::report {

Distribution from_snapshot(const rt::HistogramSnapshot& s) {
  Distribution d;
  for (std::size_t i = 0; i < s.counts.size(); ++i) {
    if (s.counts[i] == 0) continue;
    d.buckets.push_back(Bucket{static_cast<std::int64_t>(rt::Histogram::bucket_lower(i)),
                               static_cast<std::int64_t>(rt::Histogram::bucket_upper(i)),
                               s.counts[i]});
  }
  d.count = s.count;
  d.overflow = s.overflow;
  d.min_ns = static_cast<std::int64_t>(s.min_ns);
  d.max_ns = static_cast<std::int64_t>(s.max_ns);
  d.mean_ns = s.mean_ns();
  fill_percentiles(d);
  for (const rt::Outlier& o : s.worst) {
    d.worst.push_back(CycleSample{o.cycle, o.time_ns, static_cast<std::int64_t>(o.value_ns)});
  }
  return d;
}

}  // namespace crease::report
