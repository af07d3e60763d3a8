// What creased prints on stdout: one progress line a second while it runs, the summary table
// when it stops. Non-RT.
#pragma once

#include <string>

#include <vector>

#include "core/daemon/figures.h"
#include "core/plugin_host.h"

namespace crease::daemon {

// "[T s] LOOP: N cycles, wake p99 X us, overruns K; ... faults F" and each figure a plugin
// reports (its last second and its mean so far). T: seconds since start.
[[nodiscard]] std::string progress_line(const PluginHost& host, double t_s, const std::vector<FigureReading>& figures);

struct SummaryFacts {
  double ran_s = 0;              // since start
  std::string stop_reason;       // "duration reached", "SIGINT", "creasectl stop", ...
  std::vector<FigureReading> figures;  // final, read before the outputs went safe
};

// The summary table (per loop and per plugin: rate, cycles, wake-up and execution
// percentiles, overruns, state, faults, swaps), the fault count and the plugins' figures,
// printed to stdout.
void print_summary(const PluginHost& host, const SummaryFacts& facts);

}  // namespace crease::daemon
