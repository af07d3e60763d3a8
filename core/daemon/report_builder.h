// Builds the timing report (core/report) from the running host: loops, plugins, ports (every
// kind, frame channels too), events; and writes it where creased leaves it at exit.
// Non-RT; reads the RT histograms through snapshots.
#pragma once

#include <string>

#include "core/plugin_host.h"
#include "core/report/timing_report.h"

namespace crease::daemon {

struct RunFacts {
  std::string config_file;
  std::int64_t start_ns = 0;
  bool mlockall_applied = false;
  bool affinity_applied = false;
  bool sched_fifo_applied = false;
  std::string non_rt_cpus;                         // CPU list of the non-RT threads ("" = anywhere)
  std::vector<report::ThreadPlacement> threads;    // every thread, taken once the loops run
};

// Every thread of this process now, with its placement (rt::list_threads).
[[nodiscard]] std::vector<report::ThreadPlacement> thread_placements();

[[nodiscard]] report::TimingReport build_report(const PluginHost& host, const RunFacts& facts);

// The ports as the report lists them: PortRegistry::list() with its counters now.
[[nodiscard]] std::vector<report::PortTraffic> port_traffic(const PortRegistry& ports);

// Writes DIR/report.{html,json,txt} (DIR created when missing) and prints where they are; a
// file that cannot be written is logged, the others are still written. FIGURES, when given, are
// the report's figures instead of the ports' values now (after a stop: their safe values).
void write_reports(const PluginHost& host, const RunFacts& facts, const std::string& dir,
                   const std::vector<report::FigureSummary>* figures = nullptr);

}  // namespace crease::daemon
