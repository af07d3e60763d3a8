#include "core/plugin_host.h"

#include <cmath>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <thread>
#include <utility>

#include "core/errors.h"
#include "rt/clock.h"

namespace crease {

const char* to_string(HostEvent::Type t) noexcept {
  switch (t) {
    case HostEvent::Type::loaded: return "loaded";
    case HostEvent::Type::unloaded: return "unloaded";
    case HostEvent::Type::swapped: return "swapped";
    case HostEvent::Type::swap_state_lost: return "swapped (state not carried)";
    case HostEvent::Type::fault: return "fault";
    case HostEvent::Type::activated: return "activated";
    case HostEvent::Type::deactivated: return "deactivated";
    case HostEvent::Type::device_fault: return "device fault";
    case HostEvent::Type::device_recovered: return "device recovered";
    case HostEvent::Type::mark: return "mark";
  }
  return "unknown";
}

const char* health_of(const InstanceInfo& i) noexcept {
  if (i.state == RunState::faulted) return "fault";
  switch (static_cast<Status>(i.stats->last_status.load(std::memory_order_relaxed))) {
    case Status::device_fault:
    case Status::fault: return "fault";
    case Status::degraded: return "degraded";
    case Status::ok: return "ok";
  }
  return "ok";
}

PluginHost::PluginHost(std::vector<std::filesystem::path> plugin_dirs) : dirs_(std::move(plugin_dirs)) {}

PluginHost::~PluginHost() {
  stop();
  std::lock_guard lock(mu_);
  while (!managed_.empty()) managed_.pop_back();  // reverse order of loading
  retired_.clear();  // the loops are stopped: nothing runs them
}

void PluginHost::set_event_sink(EventSink sink) {
  std::lock_guard lock(mu_);
  sink_ = std::move(sink);
}

void PluginHost::record(HostEvent e) {
  if (e.time_ns == 0) e.time_ns = rt::now_ns();
  if (e.type == HostEvent::Type::fault) ++faults_;
  if (e.type == HostEvent::Type::device_fault) ++device_faults_;
  if (sink_) sink_(e);
  events_.push_back(std::move(e));
}

PluginHost::Managed* PluginHost::find(const std::string& name) {
  for (Managed& m : managed_) {
    if (m.spec.name == name) return &m;
  }
  return nullptr;
}

const PluginHost::Managed* PluginHost::find(const std::string& name) const {
  for (const Managed& m : managed_) {
    if (m.spec.name == name) return &m;
  }
  return nullptr;
}

Loop* PluginHost::find_loop(const std::string& name) const {
  for (const auto& l : loops_) {
    if (l->spec().name == name) return l.get();
  }
  return nullptr;
}

Loop& PluginHost::add_loop(const LoopSpec& spec) {
  std::lock_guard lock(mu_);
  if (find_loop(spec.name) != nullptr) throw ConfigError("loop '" + spec.name + "' is defined twice");
  if (!(spec.rate_hz > 0.0)) throw ConfigError("loop '" + spec.name + "': rate must be positive");
  if (spec.phase_ns < 0 || spec.phase_ns >= static_cast<std::int64_t>(std::llround(1e9 / spec.rate_hz)))
    throw ConfigError("loop '" + spec.name + "': phase must be in [0, period)");
  loops_.push_back(std::make_unique<Loop>(spec));
  Loop& loop = *loops_.back();
  if (running_) {
    for (const rt::SetupStep& s : loop.start()) {
      if (!s.applied) spdlog::warn("{} not applied: {}", s.what, s.why);
    }
  }
  return loop;
}

Loop::Publication PluginHost::reschedule(Loop& loop, PluginInstance* swap_to, PluginInstance* swap_from) {
  std::vector<const Managed*> mine;
  for (const Managed& m : managed_) {
    if (m.loop == &loop) mine.push_back(&m);
  }
  std::stable_sort(mine.begin(), mine.end(), [](const Managed* a, const Managed* b) { return a->spec.order < b->spec.order; });
  auto next = std::make_unique<Schedule>();
  for (const Managed* m : mine) {
    PluginInstance* inst = m->instance.get();
    next->entries.push_back({inst, inst == swap_to ? swap_from : nullptr});
  }
  // When adoption is late, Loop keeps the old schedule until reclaim() sees it adopted.
  return loop.publish(std::move(next), adopt_timeout_);
}

void PluginHost::require_no_pending(const Loop& loop, const std::string& what) const {
  if (loop.adoption_pending())
    throw Error(what + ": loop '" + loop.spec().name + "' has not adopted the previous change yet; retry");
}

void PluginHost::finish(PluginInstance& inst, bool unloaded) noexcept {
  if (unloaded) inst.drive_safe_outputs(rt::now_ns());
  inst.call_deactivate();
}

void PluginHost::retire(std::unique_ptr<PluginInstance> old, Loop& loop, Loop::Publication pub, bool unloaded) {
  if (pub.adopted) {
    finish(*old, unloaded);
    old.reset();  // destroys the object, then dlcloses its library if nothing else holds it
  } else {
    retired_.push_back(Retired{std::move(old), &loop, pub.generation, unloaded});  // freed by poll()
  }
}

void PluginHost::set_adopt_timeout(std::chrono::milliseconds t) {
  std::lock_guard lock(mu_);
  adopt_timeout_ = t;
}

std::size_t PluginHost::retired_count() const {
  std::lock_guard lock(mu_);
  return retired_.size();
}

FirewallLimits PluginHost::limits_of(const InstanceSpec& spec, const Loop& loop) {
  FirewallLimits l;
  l.budget_ns = spec.budget_ns ? *spec.budget_ns : loop.period_ns();
  l.budget_cycles = spec.budget_cycles;
  l.deactivate_on_allocation = spec.deactivate_on_allocation;
  return l;
}

void PluginHost::add_instance(const InstanceSpec& spec) {
  std::lock_guard lock(mu_);
  if (find(spec.name) != nullptr) throw ConfigError("instance '" + spec.name + "' is defined twice");
  Loop* loop = find_loop(spec.loop);
  if (loop == nullptr) throw ConfigError("instance '" + spec.name + "': no loop named '" + spec.loop + "'");
  require_no_pending(*loop, "load '" + spec.name + "'");
  std::shared_ptr<PluginLibrary> lib = PluginLibrary::open(spec.library, dirs_);
  std::unique_ptr<PluginInstance> inst;
  try {
    inst = std::make_unique<PluginInstance>(spec.name, lib, spec.params, spec.ports, ports_, &loop->log_queue(),
                                            std::make_shared<PluginStats>(), limits_of(spec, *loop));
    if (spec.enabled) inst->activate();
  } catch (...) {
    inst.reset();
    ports_.release(spec.name);
    throw;
  }
  managed_.push_back(Managed{spec, std::move(inst), loop});
  reschedule(*loop);
  record({HostEvent::Type::loaded, spec.name, spec.loop,
          lib->plugin_name() + " " + lib->plugin_version() + " from " + lib->path().string()});
}

std::vector<rt::SetupStep> PluginHost::start() {
  std::lock_guard lock(mu_);
  std::vector<rt::SetupStep> steps;
  // Lowest priority first: thread creation and stack prefault (mmap work) of the others is
  // over before the most demanding loop takes its first deadline.
  std::vector<Loop*> order;
  for (auto& l : loops_) order.push_back(l.get());
  std::stable_sort(order.begin(), order.end(), [](Loop* a, Loop* b) { return a->spec().priority < b->spec().priority; });
  for (Loop* l : order) {
    for (rt::SetupStep& s : l->start()) steps.push_back(std::move(s));
  }
  running_ = true;
  return steps;
}

bool PluginHost::running() const {
  std::lock_guard lock(mu_);
  return running_;
}

void PluginHost::stop() {
  std::lock_guard lock(mu_);
  for (auto& l : loops_) l->stop();
  drain_locked();
  const std::int64_t now = rt::now_ns();
  for (auto it = managed_.rbegin(); it != managed_.rend(); ++it) {
    PluginInstance& inst = *it->instance;
    inst.drive_safe_outputs(now);
    inst.state.store(RunState::inactive, std::memory_order_release);
    inst.call_deactivate();
  }
  running_ = false;
}

void PluginHost::swap(const std::string& name, const std::string& library, const std::optional<Params>& params) {
  std::lock_guard lock(mu_);
  Managed* m = find(name);
  if (m == nullptr) throw ConfigError("swap: no instance named '" + name + "'");
  require_no_pending(*m->loop, "swap '" + name + "'");
  std::shared_ptr<PluginLibrary> lib = PluginLibrary::open(library, dirs_);
  const Params& p = params ? *params : m->spec.params;
  auto next = std::make_unique<PluginInstance>(name, lib, p, m->spec.ports, ports_, &m->loop->log_queue(),
                                               m->instance->stats_ptr(), limits_of(m->spec, *m->loop));
  const RunState was = m->instance->state.load(std::memory_order_acquire);
  if (was == RunState::active || was == RunState::faulted) next->activate();  // throws: old untouched

  std::unique_ptr<PluginInstance> old = std::move(m->instance);
  // Named now, from the libraries themselves: the swap event is recorded when the loop adopts.
  m->swap_detail = lib->path().filename().string() + " (" + lib->plugin_name() + " " + lib->plugin_version() +
                   ") from " + lib->path().string() + ", replacing " + old->library().path().filename().string();
  m->instance = std::move(next);
  m->spec.library = library;
  if (params) m->spec.params = *params;
  const Loop::Publication pub = reschedule(*m->loop, m->instance.get(), old.get());
  retire(std::move(old), *m->loop, pub, false);
  drain_locked();  // records the swap event with its cycle
}

void PluginHost::unload(const std::string& name) {
  std::lock_guard lock(mu_);
  auto it = std::find_if(managed_.begin(), managed_.end(), [&](const Managed& m) { return m.spec.name == name; });
  if (it == managed_.end()) throw ConfigError("unload: no instance named '" + name + "'");
  Loop* loop = it->loop;
  require_no_pending(*loop, "unload '" + name + "'");
  std::unique_ptr<PluginInstance> inst = std::move(it->instance);
  const std::string loop_name = it->spec.loop;
  managed_.erase(it);
  retire(std::move(inst), *loop, reschedule(*loop), true);
  ports_.release(name);
  record({HostEvent::Type::unloaded, name, loop_name, {}});
}

void PluginHost::activate(const std::string& name) {
  std::lock_guard lock(mu_);
  Managed* m = find(name);
  if (m == nullptr) throw ConfigError("activate: no instance named '" + name + "'");
  PluginInstance& inst = *m->instance;
  const RunState st = inst.state.load(std::memory_order_acquire);
  if (st == RunState::active) return;
  if (st == RunState::deactivate_requested) throw Error("activate: instance '" + name + "' is being deactivated; retry");
  inst.call_deactivate();  // a faulted instance has not been deactivated yet if poll() did not run
  inst.activate();
  record({HostEvent::Type::activated, name, m->spec.loop, {}});
}

void PluginHost::deactivate(const std::string& name) {
  std::lock_guard lock(mu_);
  Managed* m = find(name);
  if (m == nullptr) throw ConfigError("deactivate: no instance named '" + name + "'");
  PluginInstance& inst = *m->instance;
  RunState expected = RunState::active;
  if (m->loop->running() && inst.state.compare_exchange_strong(expected, RunState::deactivate_requested)) {
    const auto until = std::chrono::steady_clock::now() + kAdoptTimeout;
    while (inst.state.load(std::memory_order_acquire) == RunState::deactivate_requested) {
      if (std::chrono::steady_clock::now() > until) throw Error("deactivate: loop '" + m->spec.loop + "' did not answer");
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  } else {
    inst.state.store(RunState::inactive, std::memory_order_release);
    inst.drive_safe_outputs(rt::now_ns());
  }
  inst.call_deactivate();
  record({HostEvent::Type::deactivated, name, m->spec.loop, {}});
}

std::string PluginHost::set_param(const std::string& name, const std::string& key, double value) {
  std::lock_guard lock(mu_);
  Managed* m = find(name);
  if (m == nullptr) return "no instance named '" + name + "'";
  return m->instance->set_param(key, value);
}

std::optional<double> PluginHost::get_param(const std::string& name, const std::string& key) const {
  std::lock_guard lock(mu_);
  const Managed* m = find(name);
  double v = 0;
  if (m == nullptr || !m->instance->get_param(key, v)) return std::nullopt;
  return v;
}

void PluginHost::poll() {
  std::lock_guard lock(mu_);
  drain_locked();
}

void PluginHost::drain_locked() {
  for (auto& l : loops_) {
    LoopEvent e;
    while (l->try_pop_event(e)) {
      const std::string name = e.instance;
      switch (e.type) {
        case LoopEvent::Type::fault: {
          Managed* m = find(name);
          std::string detail = to_string(e.fault);
          if (e.fault == FaultKind::over_budget && m) {
            detail += " (" + format_number(double(m->instance->limits().budget_ns) / 1000.0) + " us) for " +
                      std::to_string(e.code) + " consecutive cycles";
          } else if (e.fault == FaultKind::rt_allocation) {
            detail += " (" + std::to_string(e.code) + " allocations in one hook)";
          }
          record({HostEvent::Type::fault, name, l->spec().name, detail, e.cycle, e.time_ns});
          spdlog::error("instance '{}' in loop '{}' {} at cycle {}: deactivated, outputs driven safe", name,
                        l->spec().name, detail, e.cycle);
          if (m && m->instance->state.load(std::memory_order_acquire) == RunState::faulted) {
            m->instance->call_deactivate();
          }
          break;
        }
        case LoopEvent::Type::swapped:
        case LoopEvent::Type::state_not_carried: {
          Managed* m = find(name);
          std::string detail;
          if (m) detail = std::exchange(m->swap_detail, std::string());
          record({e.type == LoopEvent::Type::swapped ? HostEvent::Type::swapped : HostEvent::Type::swap_state_lost, name,
                  l->spec().name, detail, e.cycle, e.time_ns});
          break;
        }
        case LoopEvent::Type::device_fault:
          record({HostEvent::Type::device_fault, name, l->spec().name, "its device is gone: safe state commanded", e.cycle,
                  e.time_ns});
          break;
        case LoopEvent::Type::device_recovered:
          record({HostEvent::Type::device_recovered, name, l->spec().name, {}, e.cycle, e.time_ns});
          break;
        case LoopEvent::Type::deactivated: break;  // recorded by deactivate()
      }
    }
    rt::LogRecord r;
    while (l->log_queue().try_pop(r)) {
      if (r.level == rt::LogLevel::mark) {  // on the timeline, as the plugin's event (the sink logs it)
        rt::LogRecord text_only = r;
        text_only.source[0] = '\0';
        record({HostEvent::Type::mark, r.source, l->spec().name, rt::format_log_record(text_only), 0, r.time_ns});
        continue;
      }
      const std::string text = rt::format_log_record(r);
      switch (r.level) {
        case rt::LogLevel::debug: spdlog::debug("{}", text); break;
        case rt::LogLevel::info: spdlog::info("{}", text); break;
        case rt::LogLevel::warn: spdlog::warn("{}", text); break;
        case rt::LogLevel::error: spdlog::error("{}", text); break;
        case rt::LogLevel::mark: break;
      }
    }
    // Each retired instance waits for its own loop's acknowledgement, not any loop's.
    const std::uint64_t adopted = l->reclaim();
    std::erase_if(retired_, [&](Retired& r) {
      if (r.loop != l.get() || r.generation > adopted) return false;
      finish(*r.instance, r.unloaded);
      return true;
    });
  }
}

std::vector<InstanceInfo> PluginHost::instances() const {
  std::lock_guard lock(mu_);
  std::vector<InstanceInfo> out;
  for (const Managed& m : managed_) {
    const PluginInstance& i = *m.instance;
    out.push_back({m.spec.name, m.spec.loop, i.library().path().string(), i.library().plugin_name(),
                   i.library().plugin_version(), m.spec.order, i.state.load(std::memory_order_acquire),
                   i.last_fault.load(std::memory_order_relaxed), i.stats_ptr(), i.tunables(), i.limits()});
  }
  return out;
}

std::vector<const Loop*> PluginHost::loops() const {
  std::lock_guard lock(mu_);
  std::vector<const Loop*> out;
  for (const auto& l : loops_) out.push_back(l.get());
  return out;
}

std::vector<HostEvent> PluginHost::events() const {
  std::lock_guard lock(mu_);
  return events_;
}

std::uint64_t PluginHost::fault_count() const {
  std::lock_guard lock(mu_);
  return faults_;
}

std::uint64_t PluginHost::device_fault_count() const {
  std::lock_guard lock(mu_);
  return device_faults_;
}

std::size_t PluginHost::devices_in_fault() const {
  std::lock_guard lock(mu_);
  std::size_t n = 0;
  for (const Managed& m : managed_) {
    const PluginInstance& i = *m.instance;
    n += i.state.load(std::memory_order_acquire) == RunState::active &&
         static_cast<Status>(i.stats_ptr()->last_status.load(std::memory_order_relaxed)) == Status::device_fault;
  }
  return n;
}

}  // namespace crease
