#include "core/daemon/views.h"
#include "core/daemon/figures.h"
#include "core/daemon/sequences.h"
#include "core/report/report_json.h"
#include "rt/alloc_guard.h"

namespace crease::daemon {
namespace {
double us(std::uint64_t ns) { return double(ns) / 1000.0; }
}  // namespace

nlohmann::json status_view(const PluginHost& host, const RunFacts& facts, std::int64_t now_ns,
                           const control::ControlServer* server) {
  nlohmann::json s = {{"state", "running"},
          {"config", facts.config_file},
          {"uptime_s", double(now_ns - facts.start_ns) * 1e-9},
          {"loops", host.loops().size()},
          {"plugins", host.instances().size()},
          {"faults", host.fault_count()},
          {"device_faults", host.device_fault_count()},
          {"devices_in_fault", host.devices_in_fault()},
          {"sched_fifo", facts.sched_fifo_applied},
          {"mlockall", facts.mlockall_applied}};
  if (server != nullptr) {
    const control::ServerCounters c = server->counters();
    s["control"] = {{"clients", c.clients_active},
                    {"busy", c.busy},
                    {"refused", c.malformed + c.unknown_command + c.bad_argument}};
  }
  nlohmann::json sequences = sequences_view(host.ports());  // folding sequences, when any runs
  if (!sequences.empty()) s["sequences"] = std::move(sequences);
  return s;
}

nlohmann::json loops_view(const PluginHost& host) {
  nlohmann::json out = nlohmann::json::array();
  for (const Loop* l : host.loops()) {
    const auto w = l->timing().wakeup_latency.snapshot();
    const auto e = l->timing().execution.snapshot();
    out.push_back({{"name", l->spec().name},
                   {"rate_hz", l->spec().rate_hz},
                   {"priority", l->spec().priority},
                   {"cpu", l->spec().cpu},
                   {"sched_fifo", l->fifo_applied()},
                   {"cycles", l->timing().cycles.load()},
                   {"overruns", l->timing().missed_periods.load()},
                   {"missed_deadlines", l->timing().overruns.load()},
                   {"wakeup_p50_us", us(w.percentile(50))},
                   {"wakeup_p99_us", us(w.percentile(99))},
                   {"wakeup_max_us", us(w.max_ns)},
                   {"exec_p99_us", us(e.percentile(99))}});
  }
  return out;
}

nlohmann::json threads_view(const RunFacts& facts) {
  return {{"non_rt_cpus", facts.non_rt_cpus.empty() ? std::string("any") : facts.non_rt_cpus},
          {"threads", thread_placements()}};  // as the report's machine section (report_json.h)
}

nlohmann::json plugins_view(const PluginHost& host) {
  nlohmann::json out = nlohmann::json::array();
  for (const InstanceInfo& i : host.instances()) {
    nlohmann::json tunables = nlohmann::json::object();
    for (const Tunable& t : i.tunables) tunables[t.key] = {{"value", t.value}, {"min", t.lo}, {"max", t.hi}};
    const auto x = i.stats->execution.snapshot();
    out.push_back({{"name", i.name},
                   {"loop", i.loop},
                   {"order", i.order},
                   {"plugin", i.plugin},
                   {"version", i.version},
                   {"library", i.library},
                   {"state", to_string(i.state)},
                   {"last_fault", to_string(i.last_fault)},
                   {"updates", i.stats->updates.load()},
                   {"degraded", i.stats->degraded.load()},
                   {"faults", i.stats->faults.load()},
                   {"swaps", i.stats->swaps.load()},
                   {"health", health_of(i)},
                   {"device_faults", i.stats->device_faults.load()},
                   {"budget_us", us(static_cast<std::uint64_t>(i.limits.budget_ns))},
                   {"budget_cycles", i.limits.budget_cycles},
                   {"over_budget", i.stats->over_budget.load()},
                   {"rt_allocations", i.stats->rt_allocations.load()},
                   {"on_rt_allocation", i.limits.deactivate_on_allocation ? "deactivate" : "count"},
                   {"exec_p99_us", us(x.percentile(99))},
                   {"tunables", tunables}});
  }
  return out;
}

nlohmann::json ports_view(const PortRegistry& ports) {
  nlohmann::json out = nlohmann::json::array();
  for (const PortInfo& p : ports.list()) {
    nlohmann::json j = {{"name", p.name},
                        {"kind", to_string(p.kind)},
                        {"type", p.type_name},
                        {"version", p.type_version},
                        {"size", p.size},
                        {"writer", p.writer},
                        {"readers", p.readers}};
    switch (p.kind) {
      case PortKind::latest: j["writes"] = p.sequence; break;
      case PortKind::queue: j.update({{"capacity", p.capacity}, {"pushed", p.pushed}, {"dropped", p.dropped}}); break;
      case PortKind::frames:
        j.update({{"cameras", p.cameras},
                  {"published", p.sequence},
                  {"consumed", p.consumed},
                  {"overwritten", p.overwritten}});
        break;
    }
    out.push_back(std::move(j));
  }
  return out;
}

nlohmann::json stats_view(const PluginHost& host, const control::ControlServer* server) {
  nlohmann::json plugins = nlohmann::json::array();
  std::uint64_t allocations = 0;
  for (const InstanceInfo& i : host.instances()) {
    allocations += i.stats->rt_allocations.load();
    plugins.push_back({{"name", i.name},
                       {"loop", i.loop},
                       {"state", to_string(i.state)},
                       {"health", health_of(i)},
                       {"faults", i.stats->faults.load()},
                       {"device_faults", i.stats->device_faults.load()},
                       {"over_budget", i.stats->over_budget.load()},
                       {"rt_allocations", i.stats->rt_allocations.load()}});
  }
  return {{"control", server ? server->counters().to_json() : nlohmann::json()},
          {"faults", host.fault_count()},
          {"device_faults", host.device_fault_count()},
          {"rt_allocations", {{"counted", rt::alloc_hooks_installed()}, {"total", allocations}}},
          {"plugins", plugins},
          {"figures", figure_summaries(host.ports())},
          {"loops", loops_view(host)}};
}

}  // namespace crease::daemon
