#include "core/report/report_json.h"

// Field names equal the C++ member names; to_json and from_json list the same fields.
#define CREASE_J_OUT(field) j[#field] = v.field;
#define CREASE_J_IN(field) j.at(#field).get_to(v.field);

namespace crease::report {

void to_json(nlohmann::json& j, const Bucket& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(lower_ns) CREASE_J_OUT(upper_ns) CREASE_J_OUT(count)
}
void from_json(const nlohmann::json& j, Bucket& v) {
  CREASE_J_IN(lower_ns) CREASE_J_IN(upper_ns) CREASE_J_IN(count)
}

void to_json(nlohmann::json& j, const CycleSample& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(cycle) CREASE_J_OUT(time_ns) CREASE_J_OUT(value_ns)
}
void from_json(const nlohmann::json& j, CycleSample& v) {
  CREASE_J_IN(cycle) CREASE_J_IN(time_ns) CREASE_J_IN(value_ns)
}

void to_json(nlohmann::json& j, const Distribution& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(count) CREASE_J_OUT(overflow) CREASE_J_OUT(min_ns) CREASE_J_OUT(max_ns)
  CREASE_J_OUT(mean_ns) CREASE_J_OUT(p50_ns) CREASE_J_OUT(p90_ns) CREASE_J_OUT(p99_ns)
  CREASE_J_OUT(p999_ns) CREASE_J_OUT(p9999_ns) CREASE_J_OUT(worst) CREASE_J_OUT(buckets)
}
void from_json(const nlohmann::json& j, Distribution& v) {
  CREASE_J_IN(count) CREASE_J_IN(overflow) CREASE_J_IN(min_ns) CREASE_J_IN(max_ns)
  CREASE_J_IN(mean_ns) CREASE_J_IN(p50_ns) CREASE_J_IN(p90_ns) CREASE_J_IN(p99_ns)
  CREASE_J_IN(p999_ns) CREASE_J_IN(p9999_ns) CREASE_J_IN(worst) CREASE_J_IN(buckets)
}

void to_json(nlohmann::json& j, const PluginTiming& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(name) CREASE_J_OUT(library) CREASE_J_OUT(state) CREASE_J_OUT(faults)
  CREASE_J_OUT(swaps) CREASE_J_OUT(execution) CREASE_J_OUT(health) CREASE_J_OUT(budget_us)
  CREASE_J_OUT(over_budget) CREASE_J_OUT(rt_allocations) CREASE_J_OUT(device_faults)
}
void from_json(const nlohmann::json& j, PluginTiming& v) {
  CREASE_J_IN(name) CREASE_J_IN(library) CREASE_J_IN(state) CREASE_J_IN(faults)
  CREASE_J_IN(swaps) CREASE_J_IN(execution) CREASE_J_IN(health) CREASE_J_IN(budget_us)
  CREASE_J_IN(over_budget) CREASE_J_IN(rt_allocations) CREASE_J_IN(device_faults)
}

void to_json(nlohmann::json& j, const LoopTiming& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(name) CREASE_J_OUT(rate_hz) CREASE_J_OUT(priority) CREASE_J_OUT(cpu)
  CREASE_J_OUT(cycles) CREASE_J_OUT(overruns) CREASE_J_OUT(missed_deadlines)
  CREASE_J_OUT(wakeup_latency) CREASE_J_OUT(execution) CREASE_J_OUT(plugins)
}
void from_json(const nlohmann::json& j, LoopTiming& v) {
  CREASE_J_IN(name) CREASE_J_IN(rate_hz) CREASE_J_IN(priority) CREASE_J_IN(cpu)
  CREASE_J_IN(cycles) CREASE_J_IN(overruns) CREASE_J_IN(missed_deadlines)
  CREASE_J_IN(wakeup_latency) CREASE_J_IN(execution) CREASE_J_IN(plugins)
}

void to_json(nlohmann::json& j, const Event& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(time_ns) CREASE_J_OUT(kind) CREASE_J_OUT(loop) CREASE_J_OUT(plugin)
  CREASE_J_OUT(detail)
}
void from_json(const nlohmann::json& j, Event& v) {
  CREASE_J_IN(time_ns) CREASE_J_IN(kind) CREASE_J_IN(loop) CREASE_J_IN(plugin)
  CREASE_J_IN(detail)
}

void to_json(nlohmann::json& j, const FigureSummary& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(port) CREASE_J_OUT(label) CREASE_J_OUT(unit) CREASE_J_OUT(sample) CREASE_J_OUT(count)
  CREASE_J_OUT(mean) CREASE_J_OUT(last) CREASE_J_OUT(max)
}
void from_json(const nlohmann::json& j, FigureSummary& v) {
  CREASE_J_IN(port) CREASE_J_IN(label) CREASE_J_IN(unit) CREASE_J_IN(sample) CREASE_J_IN(count)
  CREASE_J_IN(mean) CREASE_J_IN(last) CREASE_J_IN(max)
}

void to_json(nlohmann::json& j, const PortTraffic& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(name) CREASE_J_OUT(kind) CREASE_J_OUT(type) CREASE_J_OUT(version)
  CREASE_J_OUT(size) CREASE_J_OUT(writer) CREASE_J_OUT(readers) CREASE_J_OUT(cameras)
  CREASE_J_OUT(capacity) CREASE_J_OUT(writes) CREASE_J_OUT(dropped) CREASE_J_OUT(consumed)
}
void from_json(const nlohmann::json& j, PortTraffic& v) {
  CREASE_J_IN(name) CREASE_J_IN(kind) CREASE_J_IN(type) CREASE_J_IN(version)
  CREASE_J_IN(size) CREASE_J_IN(writer) CREASE_J_IN(readers) CREASE_J_IN(cameras)
  CREASE_J_IN(capacity) CREASE_J_IN(writes) CREASE_J_IN(dropped) CREASE_J_IN(consumed)
}

void to_json(nlohmann::json& j, const ThreadPlacement& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(name) CREASE_J_OUT(tid) CREASE_J_OUT(cpus) CREASE_J_OUT(policy) CREASE_J_OUT(priority)
}
void from_json(const nlohmann::json& j, ThreadPlacement& v) {
  CREASE_J_IN(name) CREASE_J_IN(tid) CREASE_J_IN(cpus) CREASE_J_IN(policy) CREASE_J_IN(priority)
}

void to_json(nlohmann::json& j, const MachineInfo& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(hostname) CREASE_J_OUT(kernel) CREASE_J_OUT(cpu_model) CREASE_J_OUT(cpu_count)
  CREASE_J_OUT(preemption) CREASE_J_OUT(sched_fifo_applied) CREASE_J_OUT(affinity_applied)
  CREASE_J_OUT(mlockall_applied) CREASE_J_OUT(non_rt_cpus) CREASE_J_OUT(threads)
}
void from_json(const nlohmann::json& j, MachineInfo& v) {
  CREASE_J_IN(hostname) CREASE_J_IN(kernel) CREASE_J_IN(cpu_model) CREASE_J_IN(cpu_count)
  CREASE_J_IN(preemption) CREASE_J_IN(sched_fifo_applied) CREASE_J_IN(affinity_applied)
  CREASE_J_IN(mlockall_applied) CREASE_J_IN(non_rt_cpus) CREASE_J_IN(threads)
}

void to_json(nlohmann::json& j, const TimingReport& v) {
  j = nlohmann::json::object();
  CREASE_J_OUT(title) CREASE_J_OUT(config_file) CREASE_J_OUT(start_ns) CREASE_J_OUT(end_ns)
  CREASE_J_OUT(wall_clock) CREASE_J_OUT(machine) CREASE_J_OUT(loops) CREASE_J_OUT(ports)
  CREASE_J_OUT(events) CREASE_J_OUT(figures)
  j["duration_s"] = v.duration_s();
}
void from_json(const nlohmann::json& j, TimingReport& v) {
  CREASE_J_IN(title) CREASE_J_IN(config_file) CREASE_J_IN(start_ns) CREASE_J_IN(end_ns)
  CREASE_J_IN(wall_clock) CREASE_J_IN(machine) CREASE_J_IN(loops) CREASE_J_IN(ports)
  CREASE_J_IN(events)
  if (j.contains("figures")) CREASE_J_IN(figures)  // reports written before figures had none
}

}  // namespace crease::report
