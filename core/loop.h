// A loop: one periodic RT thread running an ordered schedule of plugin instances.
//
// The schedule is immutable while published. To change it (load, unload, hot-swap) the host
// builds a new one off the RT thread and publishes it; at its next cycle boundary the loop
// adopts it, carries state from replaced instances to their successors (save_state ->
// load_state into a preallocated buffer) and acknowledges by publishing the schedule's
// generation. Only then may the host free the old schedule and what it alone referenced
// (ros2_control's RTControllerListWrapper pattern, with atomics and stated orders). Each
// publication has its own generation: what a schedule of generation g replaced may be freed
// once this loop's adopted_generation() >= g, whatever other loops do.
//
// A cycle has two phases: every active instance's update in run order (read inputs, compute,
// write outputs), then the write hook of those that have one, in run order (a driver sends the
// command a controller computed in this cycle's update: sensing to command in one cycle).
//
// The firewall: an update or write that returns fault, throws, returns an unknown code or
// writes a non-finite output stops that instance (outputs driven safe, state faulted) and is
// reported as an event; the loop keeps its timing and runs the others. So is an instance whose
// update + write ran longer than its time budget (FirewallLimits) for budget_cycles cycles in
// a row, measured with the two clock reads per hook the loop makes anyway, less the time the loop
// thread was preempted (rt::charged_hook_ns; blocking is charged in full). The thread's CPU clock
// is sampled only in the cycles after one that ran over by the wall clock, so such a run's first
// cycle is not counted, and budget_cycles + 1 cycles over it stop an instance. And, when its
// limits say so, one that allocated on the heap in a hook. Allocations are counted per
// instance (PluginStats::rt_allocations) from the loop thread's own counter
// (rt::this_thread_rt_allocations: one load before and one after each hook) while
// count_allocations is on (the default). A hook returning Status::device_fault is not a
// firewall fault: the instance stays scheduled, and each change into and out of it is an event.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/plugin_instance.h"
#include "rt/log_queue.h"
#include "rt/periodic_loop.h"
#include "rt/thread_cpu.h"
#include "rt/queue.h"

namespace crease {

struct LoopSpec {
  std::string name;
  double rate_hz = 1000.0;
  int priority = 0;  // 0 = SCHED_OTHER, 1..99 = SCHED_FIFO
  int cpu = -1;      // -1 = any
  std::int64_t phase_ns = 0;  // deadlines at k period + phase_ns of CLOCK_MONOTONIC, [0, period)
};

struct Schedule {
  struct Entry {
    PluginInstance* instance = nullptr;
    PluginInstance* takes_state_from = nullptr;  // set for the new version in a hot-swap
    mutable std::int64_t update_ns = 0;          // loop thread only: this cycle's update time
    mutable std::int64_t update_t0 = 0;          // loop thread only: when this cycle's update started
    mutable Status update_status = Status::ok;   // loop thread only: what this cycle's update returned
  };
  std::vector<Entry> entries;  // in run order
  std::uint64_t generation = 0;
};

// Reported by the loop thread, consumed by the host (non-RT).
struct LoopEvent {
  // fault: the firewall stopped it (fault says why; code: the plugin's return code, the budget's
  // cycles for over_budget, the allocations of the hook for rt_allocation).
  enum class Type : std::uint8_t { fault, swapped, deactivated, state_not_carried, device_fault, device_recovered };
  Type type = Type::fault;
  FaultKind fault = FaultKind::none;
  std::int32_t code = 0;
  std::uint64_t cycle = 0;
  std::int64_t time_ns = 0;
  char instance[48] = {};  // instance name (copied: the instance may be gone when this is read)
};

class Loop {
 public:
  static constexpr std::size_t kStateBufferBytes = 64 * 1024;

  explicit Loop(LoopSpec spec);
  ~Loop();
  Loop(const Loop&) = delete;
  Loop& operator=(const Loop&) = delete;

  // Non-RT.
  std::vector<rt::SetupStep> start();
  void stop();
  [[nodiscard]] bool running() const noexcept { return thread_.running(); }

  struct Publication {
    std::uint64_t generation = 0;  // of the published schedule
    bool adopted = false;          // the loop adopted it within the timeout
  };
  // Non-RT, one caller at a time, and only while no publication is pending (adoption_pending()
  // false; a bug otherwise). Publishes `next`. When the loop runs, waits (up to `timeout`) for
  // the loop thread to adopt it; when it does not run, adopts it here. Schedules the loop has
  // moved past are freed here and by reclaim().
  Publication publish(std::unique_ptr<Schedule> next, std::chrono::milliseconds timeout);
  // Non-RT: frees the schedules the loop has moved past; returns adopted_generation().
  std::uint64_t reclaim();
  // A publication the loop thread has not adopted yet (a late adoption).
  [[nodiscard]] bool adoption_pending() const noexcept { return pending_.load(std::memory_order_acquire) != nullptr; }
  // Generation of the schedule the loop runs (any thread).
  [[nodiscard]] std::uint64_t adopted_generation() const noexcept { return adopted_.load(std::memory_order_acquire); }
  [[nodiscard]] const Schedule* schedule() const noexcept { return current_.load(std::memory_order_acquire); }

  // Non-RT: events from the loop thread.
  bool try_pop_event(LoopEvent& e) noexcept { return events_.try_pop(&e); }
  [[nodiscard]] std::uint64_t events_dropped() const noexcept { return events_.dropped(); }

  [[nodiscard]] const LoopSpec& spec() const noexcept { return spec_; }
  [[nodiscard]] const rt::LoopTiming& timing() const noexcept { return thread_.timing(); }
  [[nodiscard]] bool fifo_applied() const noexcept { return thread_.fifo_applied(); }
  [[nodiscard]] rt::RtLogQueue& log_queue() noexcept { return log_; }
  [[nodiscard]] std::int64_t period_ns() const noexcept { return thread_.settings().period_ns; }

  // Whether hooks' heap allocations are counted per instance (default on). Any thread; the loop
  // reads it once per cycle.
  void set_count_allocations(bool on) noexcept { count_allocations_.store(on, std::memory_order_relaxed); }
  [[nodiscard]] bool count_allocations() const noexcept { return count_allocations_.load(std::memory_order_relaxed); }

  // Whether the time budget leaves out the time the loop thread was preempted (default on; off
  // only to show what wall-time budgets do on a loaded machine). Any thread.
  void set_discount_preemption(bool on) noexcept { discount_preemption_.store(on, std::memory_order_relaxed); }

  // Runs one cycle on the calling thread (tests and benchmarks of the cycle itself).
  void run_cycle_rt(const rt::CycleClock& clock) noexcept;

 private:
  static void body(void* self, const rt::CycleClock& clock) noexcept;
  void adopt_rt(Schedule* next, const rt::CycleClock& clock) noexcept;
  void push_event_rt(const LoopEvent& e) noexcept { (void)events_.try_push(&e); }
  // Runs one phase's hook of an active instance and accounts for it: degraded and fault counts,
  // allocations (allocs: this thread's counter, or nullptr when not counting), the firewall
  // event. Returns the hook's duration (ns); t0: when it started; status: what it returned.
  std::int64_t run_hook_rt(PluginInstance& inst, bool write_phase, const crease_cycle& cycle, const std::uint64_t* allocs,
                           std::int64_t& t0, Status& status) noexcept;
  // After an instance's last hook of the cycle: its execution time (update + write), the time
  // budget, the device-fault transitions.
  void finish_instance_rt(PluginInstance& inst, std::int64_t ns, Status status, std::uint64_t cycle,
                          std::int64_t t0) noexcept;
  // A firewall stop found by the loop itself (over budget, allocation): counted, event, log.
  void trip_rt(PluginInstance& inst, FaultKind kind, std::int32_t code, std::uint64_t cycle, std::int64_t t) noexcept;

  LoopSpec spec_;
  std::atomic<Schedule*> current_{nullptr};   // in schedules_; replaced only by adopt
  std::atomic<Schedule*> pending_{nullptr};   // in schedules_; published by the host, taken by the loop
  std::atomic<std::uint64_t> adopted_{0};     // generation of the last adopted schedule
  std::vector<std::unique_ptr<Schedule>> schedules_;  // non-RT: every schedule not yet freed
  std::uint64_t published_ = 0;               // non-RT: generation of the last publication
  std::unique_ptr<unsigned char[]> state_buf_;
  std::atomic<bool> count_allocations_{true};
  std::atomic<bool> discount_preemption_{true};
  rt::ThreadCpuSample cycle_cpu_;   // loop thread: sampled at the cycle's start (budget checks)
  bool have_cycle_cpu_ = false;     // loop thread: cycle_cpu_ is this cycle's
  bool sample_next_cycle_ = false;  // loop thread: a hook ran over its budget by the wall clock
  rt::QueueChannel events_;
  rt::RtLogQueue log_;
  rt::PeriodicLoop thread_;  // last: its thread stops before the members above go
};

}  // namespace crease
