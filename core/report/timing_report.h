// The timing report's data model: plain values the daemon fills in after (or during) a run,
// rendered as text (cyclictest -h format), JSON or self-contained HTML (render.h).
// All times are ns; timestamps are CLOCK_MONOTONIC ns.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace crease::report {

// One histogram bucket holding `count` samples with lower_ns <= value <= upper_ns.
struct Bucket {
  std::int64_t lower_ns = 0;
  std::int64_t upper_ns = 0;  // inclusive
  std::uint64_t count = 0;
};

// A notable cycle: its number, when it happened, the measured value.
struct CycleSample {
  std::uint64_t cycle = 0;
  std::int64_t time_ns = 0;
  std::int64_t value_ns = 0;
};

// A distribution of durations (wake-up latency or execution time).
struct Distribution {
  std::vector<Bucket> buckets;     // ascending, non-overlapping; empty buckets may be omitted
  std::uint64_t count = 0;         // samples, including overflow
  std::uint64_t overflow = 0;      // samples above the histogram's range (in the last bucket)
  std::int64_t min_ns = 0;
  std::int64_t max_ns = 0;
  double mean_ns = 0;
  std::int64_t p50_ns = 0, p90_ns = 0, p99_ns = 0, p999_ns = 0, p9999_ns = 0;
  std::vector<CycleSample> worst;  // largest first

  [[nodiscard]] bool empty() const noexcept { return count == 0; }
};

// Fills count (when 0), p50..p9999 from the buckets: the upper bound of the bucket holding
// the sample of rank ceil(p * count), clamped to [min_ns, max_ns] when max_ns > 0.
void fill_percentiles(Distribution& d);

struct PluginTiming {
  std::string name;     // instance name
  std::string library;
  std::string state;    // e.g. "active", "inactive", "faulted"
  Distribution execution;
  std::uint64_t faults = 0;
  std::uint64_t swaps = 0;
  std::string health;               // "ok", "degraded", "fault" (its device is gone), "" unknown
  double budget_us = 0;             // the firewall's time budget per cycle; 0 = none
  std::uint64_t over_budget = 0;    // cycles over that budget
  std::uint64_t rt_allocations = 0; // heap allocations in its update/write
  std::uint64_t device_faults = 0;  // times its device went into fault
};

struct LoopTiming {
  std::string name;
  double rate_hz = 0;
  int priority = 0;  // 0 = SCHED_OTHER
  int cpu = -1;      // -1 = any
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0;          // periods skipped
  std::uint64_t missed_deadlines = 0;  // cycles that ended after their deadline
  Distribution wakeup_latency;
  Distribution execution;              // the whole cycle's plugins
  std::vector<PluginTiming> plugins;   // in run order
};

// Something that happened during the run, marked on the timeline.
struct Event {
  std::int64_t time_ns = 0;
  std::string kind;    // "hot_swap", "fault", "activate", "deactivate", "load", "unload", ...
  std::string loop;    // may be empty
  std::string plugin;  // may be empty
  std::string detail;
};

// A port as it was when the report was made: what it carries, who writes and reads it, and
// its traffic. Every kind: latest and queue ports, and frame channels (kind "frames").
struct PortTraffic {
  std::string name;
  std::string kind;                  // "latest", "queue" or "frames"
  std::string type;                  // payload type name (frames: crease.FrameSet)
  std::uint32_t version = 0;
  std::uint64_t size = 0;            // bytes of one payload (frames: of one set's pixels)
  std::string writer;                // instance name; empty while unbound
  std::vector<std::string> readers;  // instance names
  std::vector<std::string> cameras;  // frames: "NAME WIDTHxHEIGHT" per camera
  std::uint64_t capacity = 0;        // queue: records
  std::uint64_t writes = 0;          // latest: writes; queue: pushed; frames: sets published
  std::uint64_t dropped = 0;         // queue: refused when full; frames: sets overwritten unread
  std::uint64_t consumed = 0;        // frames: sequence of the newest set the reader took
};

// One thread of the daemon and where it may run (rt::list_threads, taken once the loops run).
struct ThreadPlacement {
  std::string name;
  int tid = 0;
  std::string cpus;    // its affinity as a CPU list, e.g. "0" or "0-3"
  std::string policy;  // fifo, rr, other, batch, idle
  int priority = 0;
};

struct MachineInfo {
  std::string hostname;
  std::string kernel;       // uname -r + version
  std::string cpu_model;
  int cpu_count = 0;
  std::string preemption;   // "PREEMPT_RT", "PREEMPT_DYNAMIC", "PREEMPT" or "none"
  bool sched_fifo_applied = false;
  bool affinity_applied = false;
  bool mlockall_applied = false;
  std::string non_rt_cpus;               // where the non-real-time threads run ("" = anywhere)
  std::vector<ThreadPlacement> threads;  // every thread of the daemon
};

// Reads hostname, kernel, CPU model and count, preemption model. The *_applied flags are
// left false for the daemon to set.
[[nodiscard]] MachineInfo probe_machine();

// A figure a plugin reported (a latest port of type crease::Figure: core/port_types/figure.h).
struct FigureSummary {
  std::string port;
  std::string label;   // what is measured, as the plugin names it
  std::string unit;
  std::string sample;  // what one sample is
  std::uint64_t count = 0;
  double mean = 0, last = 0, max = 0;
};

struct TimingReport {
  std::string title = "Crease timing report";
  std::string config_file;
  std::int64_t start_ns = 0;  // CLOCK_MONOTONIC at start
  std::int64_t end_ns = 0;    // at the time of the report
  std::string wall_clock;     // human-readable time of the report (e.g. ISO 8601), optional
  MachineInfo machine;
  std::vector<LoopTiming> loops;
  std::vector<PortTraffic> ports;  // by name
  std::vector<Event> events;       // by time
  std::vector<FigureSummary> figures;  // by port name

  [[nodiscard]] double duration_s() const noexcept { return double(end_ns - start_ns) * 1e-9; }
};

}  // namespace crease::report
