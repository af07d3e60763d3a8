// The plugin host: loops, plugin instances, ports; load, unload, hot-swap, activate,
// deactivate, tunables; firewall events. Every method is non-RT and thread-safe (one internal
// mutex: the control server and the main thread may both call in).
//
// Refusals (a library outside the plugin directories, writable by others, without entry point,
// of another ABI; a configure error; a port mismatch) throw with a message naming the file or
// instance and the reason, and leave everything already running untouched.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/loop.h"
#include "core/params.h"
#include "core/plugin_instance.h"
#include "core/port_registry.h"
#include "rt/log_queue.h"

namespace crease {

struct InstanceSpec {
  std::string name;
  std::string library;  // "x" -> libx.so in a plugin directory, or a path inside one
  std::string loop;
  int order = 0;        // run order within the loop (ascending)
  Params params;
  std::map<std::string, std::string> ports;  // plugin port name -> global port name
  bool enabled = true;  // activated when added
  // The firewall's time budget for update + write per cycle: absent, the loop's period (an
  // instance alone taking a whole period makes the loop miss deadlines); 0, none. Over it for
  // budget_cycles consecutive cycles, the instance is stopped as a faulting one.
  std::optional<std::int64_t> budget_ns;
  std::uint32_t budget_cycles = FirewallLimits::kDefaultBudgetCycles;
  bool deactivate_on_allocation = false;  // a heap allocation in update/write stops it
};

// Something that happened to an instance, for logs and the report's timeline.
struct HostEvent {
  // mark: a plugin's log_rt(LogLevel::mark, ...), e.g. a folding sequence's transition.
  enum class Type { loaded, unloaded, swapped, swap_state_lost, fault, activated, deactivated, device_fault, device_recovered, mark };
  Type type = Type::loaded;
  std::string instance;
  std::string loop;
  std::string detail;
  std::uint64_t cycle = 0;
  std::int64_t time_ns = 0;
};
const char* to_string(HostEvent::Type t) noexcept;

struct InstanceInfo {
  std::string name, loop, library, plugin, version;
  int order = 0;
  RunState state = RunState::inactive;
  FaultKind last_fault = FaultKind::none;
  std::shared_ptr<PluginStats> stats;
  std::vector<Tunable> tunables;
  FirewallLimits limits;
};
// "fault" when the firewall stopped it or its device is gone (its last status device_fault),
// "degraded" when its last status was, else "ok".
[[nodiscard]] const char* health_of(const InstanceInfo& i) noexcept;

class PluginHost {
 public:
  using EventSink = std::function<void(const HostEvent&)>;

  explicit PluginHost(std::vector<std::filesystem::path> plugin_dirs);
  ~PluginHost();  // stop(), then unload everything in reverse order
  PluginHost(const PluginHost&) = delete;
  PluginHost& operator=(const PluginHost&) = delete;

  // Called for every event, on the thread that found it (poll() or a host call). Set it first.
  void set_event_sink(EventSink sink);

  Loop& add_loop(const LoopSpec& spec);  // throws ConfigError on a duplicate name
  // Loads, configures, activates (if enabled) and schedules. Throws; then nothing changed.
  void add_instance(const InstanceSpec& spec);
  // Starts every loop; returns the RT setup steps (applied or refused, with reasons).
  std::vector<rt::SetupStep> start();
  // Stops every loop, drives every output to its safe value, deactivates in reverse order.
  void stop();
  [[nodiscard]] bool running() const;

  // Replaces a running instance with one made from `library` (params: the old ones unless
  // given). The old one keeps running if the new one fails to load, configure or activate.
  void swap(const std::string& instance, const std::string& library, const std::optional<Params>& params = {});
  void unload(const std::string& instance);
  void activate(const std::string& instance);
  void deactivate(const std::string& instance);
  // Empty string when accepted, else the reason.
  std::string set_param(const std::string& instance, const std::string& key, double value);
  std::optional<double> get_param(const std::string& instance, const std::string& key) const;

  // Housekeeping: drains loop events (firewall faults, swaps) and RT log records, reclaims
  // late-adopted schedules. Call it periodically (the daemon does, every 50 ms).
  void poll();

  [[nodiscard]] PortRegistry& ports() noexcept { return ports_; }
  [[nodiscard]] const PortRegistry& ports() const noexcept { return ports_; }
  [[nodiscard]] std::vector<InstanceInfo> instances() const;
  [[nodiscard]] std::vector<const Loop*> loops() const;
  [[nodiscard]] std::vector<HostEvent> events() const;  // the whole timeline so far
  [[nodiscard]] std::uint64_t fault_count() const;
  // Device faults reported (Status::device_fault after another status), and how many instances
  // report one now.
  [[nodiscard]] std::uint64_t device_fault_count() const;
  [[nodiscard]] std::size_t devices_in_fault() const;
  [[nodiscard]] const std::vector<std::filesystem::path>& plugin_dirs() const noexcept { return dirs_; }

  // How long a schedule change waits for a loop to adopt it (default kAdoptTimeout). A change
  // not adopted in time goes on: what it replaced is freed by poll() once that loop adopted it,
  // and further changes to that loop are refused (Error, "retry") until then.
  static constexpr std::chrono::milliseconds kAdoptTimeout{2000};
  void set_adopt_timeout(std::chrono::milliseconds t);
  // Replaced or unloaded instances still waiting for their loop to adopt the change.
  [[nodiscard]] std::size_t retired_count() const;

 private:
  struct Managed {
    InstanceSpec spec;
    std::unique_ptr<PluginInstance> instance;
    Loop* loop = nullptr;
    std::string swap_detail;  // what the pending swap event says: the library swapped in, and out
  };
  // The firewall limits of `spec` in `loop`.
  static FirewallLimits limits_of(const InstanceSpec& spec, const Loop& loop);
  Managed* find(const std::string& name);
  const Managed* find(const std::string& name) const;
  Loop* find_loop(const std::string& name) const;
  // An instance out of every schedule published since `generation`: freed (after its hooks)
  // once its loop has adopted that generation.
  struct Retired {
    std::unique_ptr<PluginInstance> instance;
    Loop* loop = nullptr;
    std::uint64_t generation = 0;
    bool unloaded = false;  // drive its outputs safe before deactivating (an unload)
  };
  // Builds `loop`'s schedule from the managed instances, with `swap_from` carrying state into
  // `swap_to`, and publishes it.
  Loop::Publication reschedule(Loop& loop, PluginInstance* swap_to = nullptr, PluginInstance* swap_from = nullptr);
  // Throws Error when `loop` has not adopted the previous change yet (`what`: the request).
  void require_no_pending(const Loop& loop, const std::string& what) const;
  // Frees `old` now if `pub` was adopted, else keeps it in retired_ until its loop adopted.
  void retire(std::unique_ptr<PluginInstance> old, Loop& loop, Loop::Publication pub, bool unloaded);
  static void finish(PluginInstance& inst, bool unloaded) noexcept;
  void record(HostEvent e);
  void drain_locked();

  mutable std::recursive_mutex mu_;
  std::vector<std::filesystem::path> dirs_;
  PortRegistry ports_;
  std::vector<std::unique_ptr<Loop>> loops_;
  std::vector<Managed> managed_;
  std::vector<Retired> retired_;  // replaced or unloaded, awaiting a late adoption
  std::chrono::milliseconds adopt_timeout_ = kAdoptTimeout;
  std::vector<HostEvent> events_;
  std::uint64_t faults_ = 0;
  std::uint64_t device_faults_ = 0;
  EventSink sink_;
  bool running_ = false;
};

}  // namespace crease
