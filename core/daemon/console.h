// What creased prints on stdout: one progress line a second while it runs, the summary table
// when it stops. Non-RT.
#pragma once

#include <string>

#include "core/daemon/state_observer.h"
#include "core/plugin_host.h"

namespace crease::daemon {

// "[T s] LOOP: N cycles, wake p99 X us, overruns K; ... faults F" and, when the tracking is
// scored, the tracking error of the last second and the mean so far. T: seconds since start.
[[nodiscard]] std::string progress_line(const PluginHost& host, double t_s, const TrackingSummary& tracking);

struct SummaryFacts {
  double ran_s = 0;              // since start
  std::string stop_reason;       // "duration reached", "SIGINT", "creasectl stop", ...
  TrackingSummary tracking;      // final
  std::string record_state;      // the --record-state file, empty when none
};

// The summary table (per loop and per plugin: rate, cycles, wake-up and execution
// percentiles, overruns, state, faults, swaps), the fault count, the tracking error and what
// was recorded, printed to stdout.
void print_summary(const PluginHost& host, const SummaryFacts& facts);

}  // namespace crease::daemon
