// One configured plugin instance: the library it came from, the object it made, its port
// bindings, safe outputs, tunables and run state. Hooks marked _rt run on the loop thread;
// everything else is non-RT.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "core/params.h"
#include "core/plugin_library.h"
#include "core/port_binder.h"
#include "core/status.h"
#include "rt/histogram.h"
#include "rt/queue.h"

namespace crease {

enum class RunState : std::uint8_t {
  inactive,              // configured, not running
  active,                // the loop calls update
  deactivate_requested,  // the loop drives its outputs safe at the next boundary, then: inactive
  faulted,               // the firewall stopped it: outputs safe, waiting for activate
};
const char* to_string(RunState s) noexcept;

// Why the firewall stopped an instance.
enum class FaultKind : std::uint8_t {
  none,
  fault_status,
  threw,
  non_finite_output,
  bad_status,
  over_budget,    // ran longer than its time budget for budget_cycles consecutive cycles
  rt_allocation,  // allocated on the heap in update/write (only with deactivate_on_allocation)
};
const char* to_string(FaultKind k) noexcept;

// The firewall's limits of one instance beyond its statuses, fixed when it is loaded (a swap
// keeps them). Time is the instance's update plus write of one cycle, measured with the clock
// reads the loop makes anyway.
struct FirewallLimits {
  static constexpr std::uint32_t kDefaultBudgetCycles = 20;
  std::int64_t budget_ns = 0;  // 0: no time budget
  std::uint32_t budget_cycles = kDefaultBudgetCycles;  // consecutive cycles over budget before it is stopped, >= 1
  bool deactivate_on_allocation = false;  // a heap allocation in update/write stops it (else counted only)
};

// Timing and counters of one instance name; kept across hot-swaps. Written by its loop thread.
struct PluginStats {
  rt::Histogram execution;
  std::atomic<std::uint64_t> updates{0};
  std::atomic<std::uint64_t> degraded{0};
  std::atomic<std::uint64_t> faults{0};
  std::atomic<std::uint64_t> swaps{0};
  std::atomic<std::uint64_t> over_budget{0};     // cycles whose update + write exceeded the budget
  std::atomic<std::uint64_t> rt_allocations{0};  // heap allocations made in its update/write
  std::atomic<std::uint64_t> device_faults{0};   // times it reported Status::device_fault after another status
  std::atomic<std::uint8_t> last_status{0};      // Status of its last update/write phase
};

class PluginInstance {
 public:
  // Creates the plugin object and configures it. Throws (ConfigError, LoadError, PortError)
  // with a message naming the instance; on throw nothing of it remains.
  PluginInstance(std::string name, std::shared_ptr<PluginLibrary> library, const Params& params,
                 std::map<std::string, std::string> port_remap, PortRegistry& registry, rt::RtLogQueue* log,
                 std::shared_ptr<PluginStats> stats, FirewallLimits limits = {});
  ~PluginInstance();  // cleanup, destroy, then release the library
  PluginInstance(const PluginInstance&) = delete;
  PluginInstance& operator=(const PluginInstance&) = delete;

  // Non-RT. Calls the plugin's activate and marks it active. Throws Error on refusal.
  void activate();
  // Non-RT. Calls the plugin's deactivate hook (the instance must be out of the schedule or
  // not active in it).
  void call_deactivate() noexcept;
  // Non-RT: writes every safe output (only while no loop runs this instance).
  void drive_safe_outputs(std::int64_t stamp_ns) noexcept;

  // Non-RT. Validates (range, then the plugin) and queues a tunable change for the loop.
  // Returns an empty string when accepted, else the reason.
  std::string set_param(const std::string& key, double value);
  [[nodiscard]] bool get_param(const std::string& key, double& value) const;
  [[nodiscard]] std::vector<Tunable> tunables() const { return binder_.tunables(); }

  // RT side.
  void apply_param_changes_rt() noexcept;
  // Runs update and classifies the outcome; on a fault drives outputs safe and marks faulted.
  // Returns the fault kind (none when it went on).
  FaultKind update_rt(const crease_cycle& cycle, Status& status) noexcept;
  // The write phase (after every instance's update), classified as update_rt. Only when has_write().
  FaultKind write_rt(const crease_cycle& cycle, Status& status) noexcept;
  [[nodiscard]] bool has_write() const noexcept { return d_.write != nullptr; }
  // The firewall's own verdicts (loop thread): accounts one cycle's update + write time
  // against the budget; returns true when this cycle made budget_cycles in a row over it.
  bool over_budget_rt(std::int64_t cycle_ns) noexcept;
  // Stops the instance as a fault of `kind` would (outputs safe, state faulted).
  void trip_rt(FaultKind kind, std::int32_t code, std::int64_t stamp_ns) noexcept;
  [[nodiscard]] const FirewallLimits& limits() const noexcept { return limits_; }
  void drive_safe_outputs_rt(std::int64_t stamp_ns) noexcept { drive_safe_outputs(stamp_ns); }
  std::size_t save_state_rt(void* buf, std::size_t cap) noexcept { return d_.save_state(self_, buf, cap); }
  bool load_state_rt(const void* buf, std::size_t len) noexcept { return d_.load_state(self_, buf, len) == 0; }

  std::atomic<RunState> state{RunState::inactive};
  std::atomic<FaultKind> last_fault{FaultKind::none};
  std::atomic<std::int32_t> last_code{0};

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] const PluginLibrary& library() const noexcept { return *library_; }
  [[nodiscard]] PluginStats& stats() noexcept { return *stats_; }
  [[nodiscard]] const std::shared_ptr<PluginStats>& stats_ptr() const noexcept { return stats_; }
  [[nodiscard]] const std::vector<SafeOutput>& safe_outputs() const noexcept { return binder_.safe_outputs(); }

 private:
  FaultKind classify_rt(std::int32_t code, const crease_cycle& cycle, Status& status) noexcept;

  struct ParamChange {
    std::uint32_t index;
    double value;
  };

  std::shared_ptr<PluginLibrary> library_;  // first member: released last, after destroy
  const crease_plugin_descriptor& d_;
  std::string name_;
  std::shared_ptr<PluginStats> stats_;
  detail::OutputFlags flags_;
  PortBinder binder_;
  rt::QueueChannel param_changes_;  // non-RT (host, serialised) -> loop thread
  void* self_ = nullptr;
  FirewallLimits limits_;
  std::uint32_t over_budget_run_ = 0;  // loop thread: consecutive cycles over budget
  bool hook_active_ = false;  // activate hook called and not yet matched by deactivate (non-RT)
};

}  // namespace crease
