// The daemon's YAML configuration as plain structs, loaded and validated completely.
//
//   crease::config::DaemonConfig cfg = crease::config::load_daemon_config("config/sim.yaml");
//
// Every error throws ConfigError before anything is returned; its what() reads
//   FILE:LINE:COLUMN: KEY.PATH: reason        (1-based line and column)
// e.g. "sim.yaml:14:5: plugins[2].loop: unknown loop 'contrl' (did you mean 'control'?)".
// Unknown keys are errors. Durations are seconds, rates Hz. Plugin parameters are kept as
// YAML nodes (with their marks) for the owning plugin to validate.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "core/config/yaml_bounds.h"
#include "core/errors.h"

namespace crease::config {

// Where an item came from (so later errors, plugin load and parameter validation, can point
// back to it), and the error every failure throws: crease's own (core/errors.h).
using crease::ConfigError;
using crease::SourceLoc;

// "FILE:LINE:COLUMN: KEY.PATH: reason" for a YAML node of a loaded config; a plugin that
// rejects one of its params uses this so its message points into the config file.
[[nodiscard]] ConfigError error_at(const std::string& file, const YAML::Node& node,
                                   const std::string& key_path, const std::string& reason);

// daemon.control: the control socket's limits per client (core/control/control_server.h).
struct ControlSettings {
  double idle_timeout_s = 30;        // a silent client is closed after this; 0 = never
  double max_requests_per_s = 500;   // beyond it a client's requests are answered `busy`; 0 = no limit
  int max_clients = 128;             // connections at once (the idlest yields to a new one)
  SourceLoc loc;
};

struct DaemonSettings {
  std::optional<std::string> socket;        // control socket path; absent: creased's default
  std::optional<std::string> socket_group;  // group allowed on the socket (0660)
  std::optional<std::string> report_dir;    // resolved against the config file's folder
  std::optional<double> duration_s;         // > 0; absent: run until stopped
  bool lock_memory = true;                  // mlockall(MCL_CURRENT|MCL_FUTURE) + prefault
  int prefault_heap_mb = 64;                // >= 0, heap touched at start when lock_memory
  std::optional<int> cpu_dma_latency_us;    // >= 0; absent: /dev/cpu_dma_latency untouched
  // CPUs for every non-real-time thread (control server, log drain, host polling, workers);
  // absent: every CPU of the process that no loop is pinned to. A listed CPU that a loop is
  // pinned to is shared with that loop (creased says so at start): e.g. a simulated world's.
  std::optional<std::vector<int>> non_rt_cpus;
  SourceLoc non_rt_cpus_loc;
  ControlSettings control;
  // After SIGINT/SIGTERM during start-up: how long the stage under way (a plugin's configure,
  // the prefault) and the unwinding may take before creased exits without unwinding
  // (core/daemon/startup_stop.h). [0, 3600] s; 0 = wait for the stage however long.
  double startup_stop_grace_s = 0.5;
  SourceLoc loc;
};

enum class OverrunPolicy { skip };  // missed periods are skipped and counted

struct LoopConfig {
  std::string name;   // [a-z][a-z0-9_]*
  double rate_hz = 0; // (0, 20000]
  int priority = 0;   // 0 = SCHED_OTHER, 1..99 = SCHED_FIFO
  int cpu = -1;       // -1 = any, else 0..1023
  std::int64_t phase_ns = 0;  // phase_us: deadlines at k period + phase of CLOCK_MONOTONIC, [0, period)
  OverrunPolicy overrun = OverrunPolicy::skip;
  SourceLoc loc;

  // Period in CLOCK_MONOTONIC ns, rounded to the nearest ns.
  [[nodiscard]] std::int64_t period_ns() const noexcept;
};

enum class FaultPolicy { deactivate, stop };
// What a heap allocation in a plugin's update/write does: always counted; `deactivate` also
// stops the plugin as a fault would.
enum class AllocationPolicy { count, deactivate };

// The firewall's time budget of one instance: `budget: {time_us: T, cycles: N}`.
struct BudgetConfig {
  std::optional<double> time_us;  // [0, 1e7]; 0 = no budget; absent: the loop's period
  int cycles = 20;                // [1, 1000000]: consecutive cycles over budget before it is stopped
  SourceLoc loc;
};

struct PluginConfig {
  std::string name;     // instance name, [a-z][a-z0-9_]*, unique
  std::string library;  // "crease_counter" -> libcrease_counter.so in a plugin dir, or a path
  std::string loop;     // names a LoopConfig
  int order = 0;        // run order within the loop (ascending); unique per loop
  bool enabled = true;
  YAML::Node params;    // a map (possibly empty), marks kept; validated by the plugin
  std::map<std::string, std::string> ports;  // local port name -> global port name
  BudgetConfig budget;
  std::optional<AllocationPolicy> on_rt_allocation;  // absent: safety.on_rt_allocation
  SourceLoc loc;        // the list item
  SourceLoc params_loc; // the params map, or the item when absent
};


struct SafetyConfig {
  FaultPolicy on_fault = FaultPolicy::deactivate;
  double max_overruns_per_s = 0;  // 0 = no limit; else stop when exceeded
  AllocationPolicy on_rt_allocation = AllocationPolicy::count;  // every instance's default
  SourceLoc loc;
};

struct DaemonConfig {
  std::string file;                      // as given (or the virtual name)
  std::vector<std::string> plugin_dirs;  // absolute or resolved against the file's folder
  DaemonSettings daemon;
  std::vector<LoopConfig> loops;         // in file order
  std::vector<PluginConfig> plugins;     // in file order
  SafetyConfig safety;

  [[nodiscard]] const LoopConfig* find_loop(const std::string& name) const;
  [[nodiscard]] const PluginConfig* find_plugin(const std::string& name) const;
  // Plugins of one loop sorted by order.
  [[nodiscard]] std::vector<const PluginConfig*> plugins_of_loop(const std::string& loop) const;
};

struct LoadOptions {
  // Refuse plugin_dirs that do not exist or are not directories.
  bool check_plugin_dirs_exist = true;
  // The file's size and node count (aliases expanded): past them, a ConfigError at the byte
  // or node where the limit is crossed, before any walk of the tree (yaml_bounds.h).
  YamlBounds bounds{};
};

// Loads FILE; relative paths resolve against FILE's folder. Reads at most
// options.bounds.max_bytes + 1 bytes of it (a FIFO or /dev/zero too).
// @throws ConfigError (also for an unreadable file: "FILE:0:0: (file): cannot read: ...").
[[nodiscard]] DaemonConfig load_daemon_config(const std::string& path,
                                              const LoadOptions& options = {});

// Parses TEXT as if read from VIRTUAL_FILE (used in messages and to resolve relative paths).
// @throws ConfigError
[[nodiscard]] DaemonConfig load_daemon_config_from_string(const std::string& text,
                                                          const std::string& virtual_file,
                                                          const LoadOptions& options = {});

// Applies a command-line override `INSTANCE.KEY=VALUE` (creased --set): the plugin instance's
// parameter KEY becomes VALUE read as a YAML scalar. The plugin validates it as any parameter.
// Throws ConfigError naming the assignment when it is malformed or names no instance.
void override_param(DaemonConfig& config, const std::string& assignment);

[[nodiscard]] const char* to_string(OverrunPolicy p) noexcept;
[[nodiscard]] const char* to_string(FaultPolicy p) noexcept;
[[nodiscard]] const char* to_string(AllocationPolicy p) noexcept;

}  // namespace crease::config
