#include "core/plugin_instance.h"

#include <cmath>

#include "core/assert.h"
#include "core/plugin.h"

namespace crease {

const char* to_string(RunState s) noexcept {
  switch (s) {
    case RunState::inactive: return "inactive";
    case RunState::active: return "active";
    case RunState::deactivate_requested: return "deactivating";
    case RunState::faulted: return "faulted";
  }
  return "unknown";
}

const char* to_string(FaultKind k) noexcept {
  switch (k) {
    case FaultKind::none: return "none";
    case FaultKind::fault_status: return "returned fault";
    case FaultKind::threw: return "threw an exception";
    case FaultKind::non_finite_output: return "wrote a non-finite output";
    case FaultKind::bad_status: return "returned an unknown status";
    case FaultKind::over_budget: return "ran over its time budget";
    case FaultKind::rt_allocation: return "allocated on the heap in a real-time hook";
  }
  return "unknown";
}

PluginInstance::PluginInstance(std::string name, std::shared_ptr<PluginLibrary> library, const Params& params,
                               std::map<std::string, std::string> port_remap, PortRegistry& registry,
                               rt::RtLogQueue* log, std::shared_ptr<PluginStats> stats, FirewallLimits limits)
    : library_(std::move(library)),
      d_(library_->descriptor()),
      name_(std::move(name)),
      stats_(std::move(stats)),
      binder_(registry, name_, std::move(port_remap), &flags_, log),
      param_changes_(sizeof(ParamChange), 64),
      limits_(limits) {
  if (limits_.budget_cycles == 0) limits_.budget_cycles = 1;
  const std::string who = "instance '" + name_ + "' (" + library_->path().filename().string() + ")";
  self_ = d_.create();
  if (self_ == nullptr) throw LoadError(who + ": the plugin could not create an instance");
  char err[1024] = {};
  ConfigureContext ctx{&params, &binder_};
  if (d_.configure(self_, &ctx, err, sizeof(err)) != 0) {
    d_.destroy(self_);
    throw ConfigError(who + ": configure failed: " + err);
  }
  std::string problems;
  for (const std::string& k : params.unused_keys()) problems += "\n  " + k + ": unknown parameter";
  for (const std::string& p : binder_.unused_remaps()) problems += "\n  ports." + p + ": the plugin has no port '" + p + "'";
  if (!problems.empty()) {
    d_.cleanup(self_);
    d_.destroy(self_);
    throw ConfigError(who + ": configuration not understood:" + problems);
  }
}

PluginInstance::~PluginInstance() {
  if (self_ != nullptr) {
    call_deactivate();
    d_.cleanup(self_);
    d_.destroy(self_);
  }
}

void PluginInstance::activate() {
  char err[1024] = {};
  flags_.non_finite = false;
  if (d_.activate(self_, err, sizeof(err)) != 0) {
    throw Error("instance '" + name_ + "': activate failed: " + err);
  }
  hook_active_ = true;
  over_budget_run_ = 0;  // the loop does not run it now: no race
  last_fault.store(FaultKind::none, std::memory_order_relaxed);
  state.store(RunState::active, std::memory_order_release);
}

void PluginInstance::call_deactivate() noexcept {
  if (!hook_active_) return;
  hook_active_ = false;
  d_.deactivate(self_);
}

void PluginInstance::drive_safe_outputs(std::int64_t stamp_ns) noexcept {
  for (const SafeOutput& o : binder_.safe_outputs()) o.channel->write(o.safe_value.data(), stamp_ns);
}

std::string PluginInstance::set_param(const std::string& key, double value) {
  auto& ts = binder_.tunables();
  for (std::uint32_t i = 0; i < ts.size(); ++i) {
    Tunable& t = ts[i];
    if (t.key != key) continue;
    if (!std::isfinite(value) || value < t.lo || value > t.hi) {
      return "value " + format_number(value) + " for '" + key + "' is outside [" + format_number(t.lo) + ", " +
             format_number(t.hi) + "]";
    }
    char err[512] = {};
    if (d_.validate_param(self_, key.c_str(), value, err, sizeof(err)) != 0) return std::string("refused: ") + err;
    const ParamChange c{i, value};
    if (!param_changes_.try_push(&c)) return "too many changes pending; try again";
    t.value = value;
    return {};
  }
  return "instance '" + name_ + "' has no tunable parameter '" + key + "'";
}

bool PluginInstance::get_param(const std::string& key, double& value) const {
  for (const Tunable& t : binder_.tunables()) {
    if (t.key == key) {
      value = t.value;
      return true;
    }
  }
  return false;
}

void PluginInstance::apply_param_changes_rt() noexcept {
  ParamChange c;
  auto& ts = binder_.tunables();
  while (param_changes_.try_pop(&c)) {
    CREASE_DEBUG_ASSERT(c.index < ts.size());  // set_param() queues indices into ts only
    if (c.index < ts.size()) *ts[c.index].target = c.value;
  }
}

FaultKind PluginInstance::update_rt(const crease_cycle& cycle, Status& status) noexcept {
  return classify_rt(d_.update(self_, &cycle), cycle, status);
}

FaultKind PluginInstance::write_rt(const crease_cycle& cycle, Status& status) noexcept {
  return classify_rt(d_.write(self_, &cycle), cycle, status);
}

FaultKind PluginInstance::classify_rt(std::int32_t code, const crease_cycle& cycle, Status& status) noexcept {
  FaultKind kind = FaultKind::none;
  if (flags_.non_finite) {
    kind = FaultKind::non_finite_output;
  } else if (code == 2) {
    kind = FaultKind::fault_status;
  } else if (code == 3) {
    kind = FaultKind::threw;
  } else if (code != 0 && code != 1 && code != 4) {  // ok, degraded, device_fault
    kind = FaultKind::bad_status;
  }
  status = kind == FaultKind::none ? static_cast<Status>(code) : Status::fault;
  if (kind != FaultKind::none) trip_rt(kind, code, cycle.time_ns);
  return kind;
}

bool PluginInstance::over_budget_rt(std::int64_t cycle_ns) noexcept {
  if (limits_.budget_ns <= 0) return false;
  if (cycle_ns <= limits_.budget_ns) {
    over_budget_run_ = 0;
    return false;
  }
  stats_->over_budget.fetch_add(1, std::memory_order_relaxed);
  return ++over_budget_run_ >= limits_.budget_cycles;
}

void PluginInstance::trip_rt(FaultKind kind, std::int32_t code, std::int64_t stamp_ns) noexcept {
  drive_safe_outputs(stamp_ns);
  last_code.store(code, std::memory_order_relaxed);
  last_fault.store(kind, std::memory_order_relaxed);
  state.store(RunState::faulted, std::memory_order_release);
}

}  // namespace crease
