#include "core/daemon/report_builder.h"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>

#include <spdlog/spdlog.h>

#include "core/daemon/figures.h"
#include "core/report/from_rt.h"
#include "core/report/render.h"
#include "rt/clock.h"
#include "rt/thread_placement.h"

namespace crease::daemon {

namespace {
std::string iso_now() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

const char* event_kind(HostEvent::Type t) {
  switch (t) {
    case HostEvent::Type::loaded: return "load";
    case HostEvent::Type::unloaded: return "unload";
    case HostEvent::Type::swapped: return "hot_swap";
    case HostEvent::Type::swap_state_lost: return "hot_swap";
    case HostEvent::Type::fault: return "fault";
    case HostEvent::Type::activated: return "activate";
    case HostEvent::Type::deactivated: return "deactivate";
    case HostEvent::Type::device_fault: return "device_fault";
    case HostEvent::Type::device_recovered: return "device_recovered";
    case HostEvent::Type::mark: return "mark";
  }
  return "event";
}
}  // namespace

std::vector<report::ThreadPlacement> thread_placements() {
  std::vector<report::ThreadPlacement> out;
  for (const rt::ThreadInfo& t : rt::list_threads()) {
    out.push_back({t.name, t.tid, rt::format_cpu_list(t.cpus), t.policy, t.priority});
  }
  return out;
}

report::TimingReport build_report(const PluginHost& host, const RunFacts& facts) {
  report::TimingReport r;
  r.config_file = facts.config_file;
  r.start_ns = facts.start_ns;
  r.end_ns = rt::now_ns();
  r.wall_clock = iso_now();
  r.machine = report::probe_machine();
  r.machine.mlockall_applied = facts.mlockall_applied;
  r.machine.affinity_applied = facts.affinity_applied;
  r.machine.sched_fifo_applied = facts.sched_fifo_applied;
  r.machine.non_rt_cpus = facts.non_rt_cpus;
  r.machine.threads = facts.threads;

  const auto instances = host.instances();
  for (const Loop* loop : host.loops()) {
    report::LoopTiming lt;
    const LoopSpec& spec = loop->spec();
    lt.name = spec.name;
    lt.rate_hz = spec.rate_hz;
    lt.priority = spec.priority;
    lt.cpu = spec.cpu;
    const rt::LoopTiming& t = loop->timing();
    lt.cycles = t.cycles.load();
    lt.overruns = t.missed_periods.load();
    lt.missed_deadlines = t.overruns.load();
    lt.wakeup_latency = report::from_snapshot(t.wakeup_latency.snapshot());
    lt.execution = report::from_snapshot(t.execution.snapshot());
    std::vector<const InstanceInfo*> mine;
    for (const InstanceInfo& i : instances) {
      if (i.loop == spec.name) mine.push_back(&i);
    }
    std::stable_sort(mine.begin(), mine.end(), [](auto* a, auto* b) { return a->order < b->order; });
    {
      for (const InstanceInfo* ip : mine) {
        const InstanceInfo& i = *ip;
        report::PluginTiming pt;
        pt.name = i.name;
        pt.library = i.plugin + " " + i.version;
        pt.state = to_string(i.state);
        pt.execution = report::from_snapshot(i.stats->execution.snapshot());
        pt.faults = i.stats->faults.load();
        pt.swaps = i.stats->swaps.load();
        pt.health = health_of(i);
        pt.budget_us = double(i.limits.budget_ns) / 1000.0;
        pt.over_budget = i.stats->over_budget.load();
        pt.rt_allocations = i.stats->rt_allocations.load();
        pt.device_faults = i.stats->device_faults.load();
        lt.plugins.push_back(std::move(pt));
      }
    }
    r.loops.push_back(std::move(lt));
  }
  r.ports = port_traffic(host.ports());
  for (const HostEvent& e : host.events()) {
    r.events.push_back({e.time_ns, event_kind(e.type), e.loop, e.instance, e.detail});
  }
  r.figures = figure_summaries(host.ports());
  return r;
}

std::vector<report::PortTraffic> port_traffic(const PortRegistry& ports) {
  std::vector<report::PortTraffic> out;
  for (const PortInfo& p : ports.list()) {
    report::PortTraffic t;
    t.name = p.name;
    t.kind = to_string(p.kind);
    t.type = p.type_name;
    t.version = p.type_version;
    t.size = p.size;
    t.writer = p.writer;
    t.readers = p.readers;
    t.cameras = p.cameras;
    switch (p.kind) {
      case PortKind::latest: t.writes = p.sequence; break;
      case PortKind::queue:
        t.capacity = p.capacity;
        t.writes = p.pushed;
        t.dropped = p.dropped;
        break;
      case PortKind::frames:
        t.writes = p.sequence;
        t.dropped = p.overwritten;
        t.consumed = p.consumed;
        break;
    }
    out.push_back(std::move(t));
  }
  return out;
}

void write_reports(const PluginHost& host, const RunFacts& facts, const std::string& dir,
                   const std::vector<report::FigureSummary>* figures) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  report::TimingReport r = build_report(host, facts);
  if (figures != nullptr) r.figures = *figures;
  for (const auto& [format, name] : {std::pair{report::Format::html, "report.html"}, std::pair{report::Format::json, "report.json"},
                                     std::pair{report::Format::text, "report.txt"}}) {
    const fs::path p = fs::path(dir) / name;
    std::ofstream f(p);
    f << report::render(r, format);
    if (!f) spdlog::error("cannot write report {}", p.string());
  }
  std::printf("  reports: %s/report.{html,json,txt}\n", fs::absolute(dir).string().c_str());
  std::fflush(stdout);
}

}  // namespace crease::daemon
