#include "core/daemon/console.h"

#include <cstdio>

namespace crease::daemon {
namespace {
double us(std::uint64_t ns) { return double(ns) / 1000.0; }
// ", what N" when n > 0, else nothing.
std::string counted(const char* what, std::uint64_t n) { return n > 0 ? what + std::to_string(n) : std::string(); }
}  // namespace

std::string progress_line(const PluginHost& host, double t_s, const std::vector<FigureReading>& figures) {
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
  if (const std::size_t n = host.devices_in_fault()) line += ", devices in fault " + std::to_string(n);
  return line + progress_text(figures);
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
      std::printf("    %-12s %8s %10llu %10s %10s %8.1fus %8.1fus  %s, faults %llu, swaps %llu%s%s%s\n", i.name.c_str(),
                  "", (unsigned long long)i.stats->updates.load(), "", "", us(x.max_ns), us(x.percentile(99)),
                  to_string(i.state), (unsigned long long)i.stats->faults.load(), (unsigned long long)i.stats->swaps.load(),
                  counted(", device faults ", i.stats->device_faults.load()).c_str(),
                  counted(", over budget ", i.stats->over_budget.load()).c_str(),
                  counted(", RT allocations ", i.stats->rt_allocations.load()).c_str());
    }
  }
  std::printf("  faults: %llu, device faults: %llu\n", (unsigned long long)host.fault_count(),
              (unsigned long long)host.device_fault_count());
  std::printf("%s", summary_text(f.figures).c_str());
  std::fflush(stdout);
}

}  // namespace crease::daemon
