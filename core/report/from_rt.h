// Converts the RT layer's histogram snapshots into the report's Distribution.
#pragma once

#include "core/report/timing_report.h"
#include "rt/histogram.h"

namespace crease::report {

// Non-empty buckets, count, overflow, min/max/mean, percentiles and the worst cycles.
[[nodiscard]] Distribution from_snapshot(const rt::HistogramSnapshot& snapshot);

}  // namespace crease::report
