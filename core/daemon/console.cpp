#include "core/daemon/console.h"

#include <cstdio>

namespace crease::daemon {
namespace {
double us(std::uint64_t ns) { return double(ns) / 1000.0; }
}  // namespace

std::string progress_line(const PluginHost& host, double t_s, const TrackingSummary& tracking) {
  std::string line = "[" + std::to_string(static_cast<int>(t_s)) + " s]";
  for (const Loop* l : host.loops()) {
    const auto snap = l->timing().wakeup_latency.snapshot();
    char buf[200];
    std::snprintf(buf, sizeof(buf), " %s: %llu cycles, wake p99 %.0f us, overruns %llu;", l->spec().name.c_str(),
                  (unsigned long long)l->timing().cycles.load(), us(snap.percentile(99)),
                  (unsigned long long)l->timing().missed_periods.load());
    line += buf;
  }
  line += " faults " + std::to_string(host.fault_count());
  if (tracking.scored) {
    char buf[160];
    std::snprintf(buf, sizeof(buf), "; tracking error vs truth: %.2f mm (this second), %.2f mm (mean so far)",
                  tracking.window_mean_mm, tracking.mean_mm);
    line += buf;
  }
  return line;
}

void print_summary(const PluginHost& host, const SummaryFacts& f) {
  std::printf("\ncreased: ran %.1f s (%s)\n", f.ran_s, f.stop_reason.c_str());
  std::printf("  %-14s %8s %10s %10s %10s %10s %10s %9s\n", "loop/plugin", "rate Hz", "cycles", "wake p50", "wake p99",
              "wake max", "exec p99", "overruns");
  const auto instances = host.instances();
  for (const Loop* l : host.loops()) {
    const auto w = l->timing().wakeup_latency.snapshot();
    const auto e = l->timing().execution.snapshot();
    std::printf("  %-14s %8.0f %10llu %8.1fus %8.1fus %8.1fus %8.1fus %9llu\n", l->spec().name.c_str(), l->spec().rate_hz,
                (unsigned long long)l->timing().cycles.load(), us(w.percentile(50)), us(w.percentile(99)), us(w.max_ns),
                us(e.percentile(99)), (unsigned long long)l->timing().missed_periods.load());
    for (const InstanceInfo& i : instances) {
      if (i.loop != l->spec().name) continue;
      const auto x = i.stats->execution.snapshot();
      std::printf("    %-12s %8s %10llu %10s %10s %8.1fus %8.1fus  %s, faults %llu, swaps %llu\n", i.name.c_str(), "",
                  (unsigned long long)i.stats->updates.load(), "", "", us(x.max_ns), us(x.percentile(99)),
                  to_string(i.state), (unsigned long long)i.stats->faults.load(), (unsigned long long)i.stats->swaps.load());
    }
  }
  std::printf("  faults: %llu\n", (unsigned long long)host.fault_count());
  const TrackingSummary& t = f.tracking;
  if (t.scored) {
    std::printf("  tracking error of sheet_state vs sheet_truth: mean %.2f mm over %llu model frames, last %.2f mm, "
                "worst %.2f mm\n",
                t.mean_mm, (unsigned long long)t.frames, t.last_mm, t.max_mm);
  }
  if (!f.record_state.empty()) {
    std::printf("  recorded %llu model frames to %s (%llu not seen)\n", (unsigned long long)t.recorded,
                f.record_state.c_str(), (unsigned long long)t.missed);
  }
  std::fflush(stdout);
}

}  // namespace crease::daemon
