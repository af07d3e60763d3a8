#include "core/loop.h"

#include <cmath>
#include <thread>

#include "rt/clock.h"

namespace crease {
namespace {
rt::PeriodicLoop::Settings thread_settings(const LoopSpec& s) {
  rt::PeriodicLoop::Settings t;
  t.name = s.name;
  t.period_ns = static_cast<std::int64_t>(std::llround(1e9 / s.rate_hz));
  t.thread.priority = s.priority;
  t.thread.cpu = s.cpu;
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
  current_.store(new Schedule{}, std::memory_order_release);
}

Loop::~Loop() {
  thread_.stop();
  delete pending_.exchange(nullptr);
  delete current_.exchange(nullptr);
  delete replaced_;
}

std::vector<rt::SetupStep> Loop::start() { return thread_.start(); }
void Loop::stop() { thread_.stop(); }

void Loop::body(void* self, const rt::CycleClock& clock) noexcept { static_cast<Loop*>(self)->run_cycle_rt(clock); }

std::unique_ptr<Schedule> Loop::publish(std::unique_ptr<Schedule> next, std::chrono::milliseconds timeout) {
  Schedule* raw = next.release();
  raw->generation = adopted_.load(std::memory_order_acquire) + 1;
  if (!thread_.running()) {
    const rt::CycleClock clock{0, rt::now_ns(), rt::now_ns(), period_ns()};
    Schedule* old = current_.load(std::memory_order_acquire);
    adopt_rt(raw, clock);  // no loop thread: the caller is the only one touching the schedule
    return std::unique_ptr<Schedule>(old);
  }
  Schedule* old = current_.load(std::memory_order_acquire);
  pending_.store(raw, std::memory_order_release);
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (adopted_.load(std::memory_order_acquire) < raw->generation) {
    if (std::chrono::steady_clock::now() > until) {
      replaced_ = old;  // reclaim_adopted() hands it back once the loop moved on
      return nullptr;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  return std::unique_ptr<Schedule>(old);
}

std::unique_ptr<Schedule> Loop::reclaim_adopted() {
  if (replaced_ == nullptr || pending_.load(std::memory_order_acquire) != nullptr) return nullptr;
  return std::unique_ptr<Schedule>(std::exchange(replaced_, nullptr));
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

void Loop::run_cycle_rt(const rt::CycleClock& clock) noexcept {
  if (Schedule* next = pending_.exchange(nullptr, std::memory_order_acq_rel)) adopt_rt(next, clock);
  const Schedule* s = current_.load(std::memory_order_relaxed);  // only this thread stores it while running
  const crease_cycle cycle{clock.cycle, clock.deadline_ns, clock.period_ns, clock.wake_ns};
  for (const Schedule::Entry& e : s->entries) {
    PluginInstance& inst = *e.instance;
    const RunState st = inst.state.load(std::memory_order_acquire);
    if (st == RunState::active) {
      inst.apply_param_changes_rt();
      const std::int64_t t0 = rt::now_ns();
      Status status = Status::ok;
      const FaultKind fault = inst.update_rt(cycle, status);
      const std::int64_t t1 = rt::now_ns();
      PluginStats& stats = inst.stats();
      stats.execution.record(static_cast<std::uint64_t>(t1 - t0), clock.cycle, t0);
      stats.updates.store(stats.updates.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      if (status == Status::degraded) stats.degraded.fetch_add(1, std::memory_order_relaxed);
      if (fault != FaultKind::none) {
        stats.faults.fetch_add(1, std::memory_order_relaxed);
        push_event_rt(make_event(LoopEvent::Type::fault, fault, inst.last_code.load(std::memory_order_relaxed),
                                 clock.cycle, t1, inst));
        log_.try_log(rt::LogLevel::error, inst.name().c_str(), "plugin stopped by the firewall: its outputs are safe", t1);
      }
    } else if (st == RunState::deactivate_requested) {
      inst.drive_safe_outputs_rt(cycle.time_ns);
      inst.state.store(RunState::inactive, std::memory_order_release);
      push_event_rt(make_event(LoopEvent::Type::deactivated, FaultKind::none, 0, clock.cycle, clock.wake_ns, inst));
    }
  }
}

}  // namespace crease
