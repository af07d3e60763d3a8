#include "core/loop.h"

#include <climits>
#include <cmath>
#include <thread>

#include "core/assert.h"
#include "rt/alloc_guard.h"
#include "rt/clock.h"

namespace crease {
namespace {
rt::PeriodicLoop::Settings thread_settings(const LoopSpec& s) {
  rt::PeriodicLoop::Settings t;
  t.name = s.name;
  t.period_ns = static_cast<std::int64_t>(std::llround(1e9 / s.rate_hz));
  t.thread.priority = s.priority;
  t.thread.cpu = s.cpu;
  t.phase_ns = s.phase_ns;
  return t;
}

LoopEvent make_event(LoopEvent::Type type, FaultKind fault, std::int32_t code, std::uint64_t cycle, std::int64_t time_ns,
                     const PluginInstance& inst) noexcept {
  LoopEvent e;
  e.type = type;
  e.fault = fault;
  e.code = code;
  e.cycle = cycle;
  e.time_ns = time_ns;
  rt::copy_text(e.instance, inst.name().c_str());
  return e;
}
}  // namespace

Loop::Loop(LoopSpec spec)
    : spec_(std::move(spec)),
      state_buf_(new unsigned char[kStateBufferBytes]),
      events_(sizeof(LoopEvent), 1024),
      log_(256),
      thread_(thread_settings(spec_), &Loop::body, this) {
  schedules_.push_back(std::make_unique<Schedule>());
  current_.store(schedules_.back().get(), std::memory_order_release);
}

Loop::~Loop() { thread_.stop(); }  // schedules_ frees every schedule

std::vector<rt::SetupStep> Loop::start() { return thread_.start(); }
void Loop::stop() {
  thread_.stop();
  // A publication the thread did not get to: adopted here, so nothing stays pending.
  if (Schedule* next = pending_.exchange(nullptr, std::memory_order_acq_rel)) {
    adopt_rt(next, rt::CycleClock{0, rt::now_ns(), rt::now_ns(), period_ns()});
  }
  reclaim();
}

void Loop::body(void* self, const rt::CycleClock& clock) noexcept { static_cast<Loop*>(self)->run_cycle_rt(clock); }

Loop::Publication Loop::publish(std::unique_ptr<Schedule> next, std::chrono::milliseconds timeout) {
  CREASE_DEMAND(!adoption_pending(), "a schedule published while another is pending");
  next->generation = ++published_;
  Schedule* raw = next.get();
  schedules_.push_back(std::move(next));
  if (!thread_.running()) {
    const rt::CycleClock clock{0, rt::now_ns(), rt::now_ns(), period_ns()};
    adopt_rt(raw, clock);  // no loop thread: the caller is the only one touching the schedule
    reclaim();
    return {raw->generation, true};
  }
  pending_.store(raw, std::memory_order_release);
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (adopted_.load(std::memory_order_acquire) < raw->generation) {
    if (std::chrono::steady_clock::now() >= until) return {raw->generation, false};
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  reclaim();
  return {raw->generation, true};
}

std::uint64_t Loop::reclaim() {
  const std::uint64_t adopted = adopted_.load(std::memory_order_acquire);
  // The loop runs the schedule of generation `adopted`; older ones it has left for good.
  std::erase_if(schedules_, [adopted](const std::unique_ptr<Schedule>& s) { return s->generation < adopted; });
  return adopted;
}

void Loop::adopt_rt(Schedule* next, const rt::CycleClock& clock) noexcept {
  for (const Schedule::Entry& e : next->entries) {
    if (e.takes_state_from == nullptr) continue;
    const std::size_t n = e.takes_state_from->save_state_rt(state_buf_.get(), kStateBufferBytes);
    const bool carried = n <= kStateBufferBytes && e.instance->load_state_rt(state_buf_.get(), n);
    e.instance->stats().swaps.fetch_add(1, std::memory_order_relaxed);
    push_event_rt(make_event(carried ? LoopEvent::Type::swapped : LoopEvent::Type::state_not_carried, FaultKind::none, 0,
                             clock.cycle, clock.wake_ns, *e.instance));
  }
  current_.store(next, std::memory_order_release);
  adopted_.store(next->generation, std::memory_order_release);
}

std::int64_t Loop::run_hook_rt(PluginInstance& inst, bool write_phase, const crease_cycle& cycle,
                               const std::uint64_t* allocs, std::int64_t& t0, Status& status) noexcept {
  const std::uint64_t a0 = allocs != nullptr ? *allocs : 0;
  t0 = rt::now_ns();
  status = Status::ok;
  const FaultKind fault = write_phase ? inst.write_rt(cycle, status) : inst.update_rt(cycle, status);
  const std::int64_t t1 = rt::now_ns();
  PluginStats& stats = inst.stats();
  if (status == Status::degraded) stats.degraded.fetch_add(1, std::memory_order_relaxed);
  if (fault != FaultKind::none) {
    stats.faults.fetch_add(1, std::memory_order_relaxed);
    push_event_rt(make_event(LoopEvent::Type::fault, fault, inst.last_code.load(std::memory_order_relaxed), cycle.index,
                             t1, inst));
    log_.try_log(rt::LogLevel::error, inst.name().c_str(), "plugin stopped by the firewall: its outputs are safe", t1);
  }
  // The hook ran on this thread: what the thread's counter gained since a0 is the hook's.
  const std::uint64_t made = allocs != nullptr ? *allocs - a0 : 0;
  if (made != 0) {
    stats.rt_allocations.fetch_add(made, std::memory_order_relaxed);
    if (inst.limits().deactivate_on_allocation && inst.state.load(std::memory_order_relaxed) == RunState::active) {
      trip_rt(inst, FaultKind::rt_allocation, static_cast<std::int32_t>(std::min<std::uint64_t>(made, INT32_MAX)),
              cycle.index, t1);
    }
  }
  return t1 - t0;
}

void Loop::trip_rt(PluginInstance& inst, FaultKind kind, std::int32_t code, std::uint64_t cycle, std::int64_t t) noexcept {
  inst.trip_rt(kind, code, t);
  inst.stats().faults.fetch_add(1, std::memory_order_relaxed);
  push_event_rt(make_event(LoopEvent::Type::fault, kind, code, cycle, t, inst));
  log_.try_log(rt::LogLevel::error, inst.name().c_str(), "plugin stopped by the firewall: its outputs are safe", t);
}

void Loop::finish_instance_rt(PluginInstance& inst, std::int64_t ns, Status status, std::uint64_t cycle,
                              std::int64_t t0) noexcept {
  PluginStats& stats = inst.stats();
  stats.execution.record(static_cast<std::uint64_t>(ns), cycle, t0);
  stats.updates.store(stats.updates.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  if (inst.state.load(std::memory_order_relaxed) != RunState::active) return;  // stopped by a hook: a fault
  const auto before = static_cast<Status>(stats.last_status.load(std::memory_order_relaxed));
  stats.last_status.store(static_cast<std::uint8_t>(status), std::memory_order_relaxed);
  if (status == Status::device_fault && before != Status::device_fault) {
    stats.device_faults.fetch_add(1, std::memory_order_relaxed);
    push_event_rt(make_event(LoopEvent::Type::device_fault, FaultKind::none, 0, cycle, t0, inst));
  } else if (status != Status::device_fault && before == Status::device_fault) {
    push_event_rt(make_event(LoopEvent::Type::device_recovered, FaultKind::none, 0, cycle, t0, inst));
  }
  // Over budget by the wall clock: charge only what the hook ran, not the time the thread was
  // preempted (a loaded machine's doing, not the plugin's), unless it blocked. Sampling the
  // thread's CPU clock costs about 1 us, so the loop samples only in the cycles after one that ran
  // over by the wall clock; such a first cycle is left uncounted (neither over nor within).
  const std::int64_t budget = inst.limits().budget_ns;
  std::int64_t charged = ns;
  if (budget > 0 && ns > budget && discount_preemption_.load(std::memory_order_relaxed)) {
    sample_next_cycle_ = true;
    if (!have_cycle_cpu_) return;
    charged = rt::charged_hook_ns(ns, cycle_cpu_, rt::sample_thread_cpu());
  }
  if (inst.over_budget_rt(charged)) {
    trip_rt(inst, FaultKind::over_budget, static_cast<std::int32_t>(inst.limits().budget_cycles), cycle, t0 + ns);
  }
}

void Loop::run_cycle_rt(const rt::CycleClock& clock) noexcept {
  if (Schedule* next = pending_.exchange(nullptr, std::memory_order_acq_rel)) adopt_rt(next, clock);
  const Schedule* s = current_.load(std::memory_order_relaxed);  // only this thread stores it while running
  const crease_cycle cycle{clock.cycle, clock.deadline_ns, clock.period_ns, clock.wake_ns};
  const std::uint64_t* allocs = count_allocations_.load(std::memory_order_relaxed) ? rt::this_thread_rt_allocations() : nullptr;
  have_cycle_cpu_ = sample_next_cycle_;
  sample_next_cycle_ = false;
  if (have_cycle_cpu_) cycle_cpu_ = rt::sample_thread_cpu();
  bool any_write = false;
  // Phase 1: update, in run order.
  for (const Schedule::Entry& e : s->entries) {
    PluginInstance& inst = *e.instance;
    e.update_ns = -1;  // no write phase this cycle unless its update ran and went on
    const RunState st = inst.state.load(std::memory_order_acquire);
    if (st == RunState::active) {
      inst.apply_param_changes_rt();
      std::int64_t t0 = 0;
      Status status = Status::ok;
      const std::int64_t ns = run_hook_rt(inst, false, cycle, allocs, t0, status);
      // An instance with a write phase is timed over both hooks (accounted after its write).
      if (inst.has_write() && inst.state.load(std::memory_order_relaxed) == RunState::active) {
        e.update_ns = ns;
        e.update_t0 = t0;
        e.update_status = status;
        any_write = true;
      } else {
        finish_instance_rt(inst, ns, status, clock.cycle, t0);
      }
    } else if (st == RunState::deactivate_requested) {
      inst.drive_safe_outputs_rt(cycle.time_ns);
      inst.state.store(RunState::inactive, std::memory_order_release);
      push_event_rt(make_event(LoopEvent::Type::deactivated, FaultKind::none, 0, clock.cycle, clock.wake_ns, inst));
    }
  }
  if (!any_write) return;
  // Phase 2: write, in run order, for the instances whose update ran (and did not fault) above.
  for (const Schedule::Entry& e : s->entries) {
    if (e.update_ns < 0) continue;
    PluginInstance& inst = *e.instance;
    std::int64_t t0 = 0;
    Status status = Status::ok;
    const std::int64_t ns = run_hook_rt(inst, true, cycle, allocs, t0, status);
    finish_instance_rt(inst, e.update_ns + ns, worst(e.update_status, status), clock.cycle, e.update_t0);
  }
}

}  // namespace crease
