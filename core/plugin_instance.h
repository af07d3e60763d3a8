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
enum class FaultKind : std::uint8_t { none, fault_status, threw, non_finite_output, bad_status };
const char* to_string(FaultKind k) noexcept;

// Timing and counters of one instance name; kept across hot-swaps. Written by its loop thread.
struct PluginStats {
  rt::Histogram execution;
  std::atomic<std::uint64_t> updates{0};
  std::atomic<std::uint64_t> degraded{0};
  std::atomic<std::uint64_t> faults{0};
  std::atomic<std::uint64_t> swaps{0};
};

class PluginInstance {
 public:
  // Creates the plugin object and configures it. Throws (ConfigError, LoadError, PortError)
  // with a message naming the instance; on throw nothing of it remains.
  PluginInstance(std::string name, std::shared_ptr<PluginLibrary> library, const Params& params,
                 std::map<std::string, std::string> port_remap, PortRegistry& registry, rt::RtLogQueue* log,
                 std::shared_ptr<PluginStats> stats);
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
  bool hook_active_ = false;  // activate hook called and not yet matched by deactivate (non-RT)
};

}  // namespace crease
