// A small synthetic report shared by the report tests (fixed values, no randomness).
#pragma once

#include "core/report/timing_report.h"

namespace crease::report::testing {

// Wake-up latencies: 1000 samples at 5 us, 100 at 20 us, 10 at 150 us, and 2 at 15 ms (above
// the text histogram's 10 ms range), on cycles 7 and 900.
inline Distribution wakeup_fixture() {
  Distribution d;
  d.buckets = {{5000, 5099, 1000}, {20000, 20499, 100}, {150000, 153999, 10},
               {15000000, 15499999, 2}};
  d.min_ns = 5000;
  d.max_ns = 15200000;
  d.mean_ns = (1000 * 5000.0 + 100 * 20000.0 + 10 * 150000.0 + 2 * 15200000.0) / 1112.0;
  d.worst = {{900, 1'900'000'000, 15200000}, {7, 1'007'000'000, 15100000},
             {55, 1'055'000'000, 150000}};
  fill_percentiles(d);
  return d;
}

inline Distribution exec_fixture(std::int64_t base_ns) {
  Distribution d;
  d.buckets = {{base_ns, base_ns + 99, 900}, {2 * base_ns, 2 * base_ns + 199, 100}};
  d.min_ns = base_ns;
  d.max_ns = 2 * base_ns + 150;
  d.mean_ns = 1.1 * static_cast<double>(base_ns);
  fill_percentiles(d);
  return d;
}

// A latest port, a queue and a frame channel, as the daemon lists them.
inline void ports_fixture(TimingReport& r) {
  PortTraffic state{"sheet_state", "latest", "crease.SheetState", 1, 360000, "sheet", {"ctrl"}, {}, 0, 120, 0, 0};
  PortTraffic crease{"crease", "queue", "crease.SheetCreaseEvent", 1, 32, "seq", {"sheet"}, {}, 256, 5, 1, 0};
  PortTraffic images{"images",  "frames", "crease.FrameSet", 1, 2457600, "cameras", {"vision"},
                     {"cam0 1280x960", "cam1 1280x960"}, 0, 30, 4, 29};
  r.ports = {crease, images, state};
}

inline TimingReport report_fixture() {
  TimingReport r;
  r.title = "Crease timing report <test & \"quotes\">";
  r.config_file = "config/sim.yaml";
  r.start_ns = 1'000'000'000;
  r.end_ns = 3'000'000'000;
  r.wall_clock = "2026-11-21T22:00:00Z";
  r.machine = probe_machine();
  r.machine.sched_fifo_applied = true;
  r.machine.affinity_applied = false;
  r.machine.mlockall_applied = true;
  LoopTiming control;
  control.name = "control";
  control.rate_hz = 1000;
  control.priority = 80;
  control.cpu = 1;
  control.cycles = 1112;
  control.overruns = 2;
  control.missed_deadlines = 3;
  control.wakeup_latency = wakeup_fixture();
  control.execution = exec_fixture(3000);
  control.plugins = {{"counter", "crease_counter", "active", exec_fixture(1000), 0, 1},
                     {"faulty", "crease_faulty", "faulted", exec_fixture(2000), 1, 0}};
  LoopTiming model;
  model.name = "model";
  model.rate_hz = 60;
  model.cycles = 120;
  model.wakeup_latency.buckets = {{40000, 40999, 120}};
  model.wakeup_latency.min_ns = 40100;
  model.wakeup_latency.max_ns = 40900;
  model.wakeup_latency.mean_ns = 40500;
  fill_percentiles(model.wakeup_latency);
  model.execution = exec_fixture(500000);
  r.loops = {control, model};
  ports_fixture(r);
  r.events = {{1'500'000'000, "hot_swap", "control", "counter", "crease_counter 1.0 -> 1.1"},
              {2'500'000'000, "fault", "control", "faulty", "NaN on output <out>"}};
  return r;
}

}  // namespace crease::report::testing
