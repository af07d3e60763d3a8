#include "core/config/daemon_config.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_set>

#include "core/config/yaml_reader.h"

namespace crease::config {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxRateHz = 20000.0;

bool is_identifier(const std::string& s) {
  if (s.empty() || !(s[0] >= 'a' && s[0] <= 'z')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

bool has_space(const std::string& s) {
  return std::any_of(s.begin(), s.end(), [](char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\0';
  });
}

std::string index_path(const std::string& key, std::size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

std::string read_identifier(const std::string& file, const YAML::Node& node,
                            const std::string& path) {
  std::string s = read_string(file, node, path);
  if (!is_identifier(s)) {
    throw ConfigError(loc_of(file, node), path,
                      "'" + s + "' is not a valid name ([a-z][a-z0-9_]*)");
  }
  return s;
}

// Resolves P against the config file's folder unless absolute.
std::string resolve(const std::string& file, const std::string& p) {
  const fs::path path(p);
  if (path.is_absolute()) return path.lexically_normal().string();
  fs::path base = fs::path(file).parent_path();
  if (base.empty()) base = ".";
  return (base / path).lexically_normal().string();
}

// Plugins read their params by key: a repeated key would silently hide one of the values.
void check_no_duplicate_keys(const std::string& file, const YAML::Node& node,
                             const std::string& path) {
  if (node.IsMap()) {
    std::unordered_set<std::string> seen;  // a flat map of many keys stays linear
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string key = it->first.IsScalar() ? it->first.Scalar() : std::string("?");
      if (it->first.IsScalar() && !seen.insert(key).second) {
        throw ConfigError(loc_of(file, it->first), path + "." + key, "duplicate key '" + key + "'");
      }
      check_no_duplicate_keys(file, it->second, path + "." + key);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      check_no_duplicate_keys(file, node[i], path + "[" + std::to_string(i) + "]");
    }
  }
}

void read_plugin_dirs(const MapReader& root, const LoadOptions& options, DaemonConfig& cfg) {
  const YAML::Node dirs = root.require("plugin_dirs");
  const std::string& file = root.file();
  if (!dirs.IsSequence() || dirs.size() == 0) {
    throw ConfigError(loc_of(file, dirs), "plugin_dirs", "expected a non-empty list of folders");
  }
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const std::string path = index_path("plugin_dirs", i);
    const std::string dir = resolve(file, read_string(file, dirs[i], path));
    if (options.check_plugin_dirs_exist) {
      std::error_code ec;
      if (!fs::is_directory(dir, ec)) {
        throw ConfigError(loc_of(file, dirs[i]), path, "'" + dir + "' is not a directory");
      }
    }
    cfg.plugin_dirs.push_back(dir);
  }
}

void read_daemon(const MapReader& root, DaemonConfig& cfg) {
  if (!root.has("daemon")) return;
  const MapReader m(root.file(), root.get("daemon"), "daemon",
                    {"socket", "socket_group", "report_dir", "duration_s", "lock_memory",
                     "prefault_heap_mb", "cpu_dma_latency_us", "non_rt_cpus", "control", "startup_stop_grace_s"});
  const std::string& f = m.file();
  DaemonSettings& d = cfg.daemon;
  d.loc = m.loc();
  if (m.has("socket")) {
    d.socket = resolve(f, read_string(f, m.get("socket"), m.path_of("socket")));
  }
  if (m.has("socket_group")) {
    d.socket_group = read_string(f, m.get("socket_group"), m.path_of("socket_group"));
  }
  if (m.has("report_dir")) {
    d.report_dir = resolve(f, read_string(f, m.get("report_dir"), m.path_of("report_dir")));
  }
  if (m.has("duration_s")) {
    d.duration_s = read_number(f, m.get("duration_s"), m.path_of("duration_s"), 0.0, 1e9, true);
  }
  if (m.has("lock_memory")) {
    d.lock_memory = read_bool(f, m.get("lock_memory"), m.path_of("lock_memory"));
  }
  if (m.has("prefault_heap_mb")) {
    d.prefault_heap_mb = static_cast<int>(
        read_int(f, m.get("prefault_heap_mb"), m.path_of("prefault_heap_mb"), 0, 65536));
  }
  if (m.has("cpu_dma_latency_us")) {
    d.cpu_dma_latency_us = static_cast<int>(read_int(
        f, m.get("cpu_dma_latency_us"), m.path_of("cpu_dma_latency_us"), 0, 100000000));
  }
  if (m.has("non_rt_cpus")) {
    const YAML::Node list = m.get("non_rt_cpus");
    const std::string path = m.path_of("non_rt_cpus");
    d.non_rt_cpus_loc = loc_of(f, list);
    if (!list.IsSequence() || list.size() == 0) {
      throw ConfigError(loc_of(f, list), path, "expected a non-empty list of CPU indices, e.g. [0]");
    }
    std::vector<int> cpus;
    for (std::size_t i = 0; i < list.size(); ++i) {
      cpus.push_back(static_cast<int>(read_int(f, list[i], path + "[" + std::to_string(i) + "]", 0, 1023)));
    }
    d.non_rt_cpus = cpus;
  }
  if (m.has("startup_stop_grace_s")) {
    d.startup_stop_grace_s =
        read_number(f, m.get("startup_stop_grace_s"), m.path_of("startup_stop_grace_s"), 0.0, 3600.0, false);
  }
  if (m.has("control")) {
    const MapReader c(f, m.get("control"), m.path_of("control"), {"idle_timeout_s", "max_requests_per_s", "max_clients"});
    d.control.loc = c.loc();
    if (c.has("idle_timeout_s")) {
      d.control.idle_timeout_s = read_number(f, c.get("idle_timeout_s"), c.path_of("idle_timeout_s"), 0.0, 86400.0, false);
    }
    if (c.has("max_requests_per_s")) {
      d.control.max_requests_per_s =
          read_number(f, c.get("max_requests_per_s"), c.path_of("max_requests_per_s"), 0.0, 1e6, false);
    }
    if (c.has("max_clients")) {
      d.control.max_clients = static_cast<int>(read_int(f, c.get("max_clients"), c.path_of("max_clients"), 1, 4096));
    }
  }
}


void read_loops(const MapReader& root, DaemonConfig& cfg) {
  const std::string& f = root.file();
  const YAML::Node loops = root.require("loops");
  if (!loops.IsSequence() || loops.size() == 0) {
    throw ConfigError(loc_of(f, loops), "loops", "expected a non-empty list of loops");
  }
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const MapReader m(f, loops[i], index_path("loops", i),
                      {"name", "rate_hz", "priority", "cpu", "phase_us", "overrun"});
    LoopConfig loop;
    loop.loc = m.loc();
    loop.name = read_identifier(f, m.require("name"), m.path_of("name"));
    for (const auto& other : cfg.loops) {
      if (other.name == loop.name) {
        throw ConfigError(loc_of(f, m.get("name")), m.path_of("name"),
                          "duplicate loop name '" + loop.name + "' (first at " +
                              other.loc.str() + ")");
      }
    }
    loop.rate_hz = read_number(f, m.require("rate_hz"), m.path_of("rate_hz"), 0.0, kMaxRateHz,
                               true);
    loop.priority = static_cast<int>(read_int(f, m.require("priority"), m.path_of("priority"), 0, 99));
    if (m.has("cpu")) {
      loop.cpu = static_cast<int>(read_int(f, m.get("cpu"), m.path_of("cpu"), -1, 1023));
    }
    if (m.has("phase_us")) {
      const double period_us = 1e-3 * static_cast<double>(loop.period_ns());
      const double phase_us = read_number(f, m.get("phase_us"), m.path_of("phase_us"), 0.0, period_us, false);
      if (!(phase_us < period_us)) {
        throw ConfigError(loc_of(f, m.get("phase_us")), m.path_of("phase_us"),
                          "must be below the loop's period (" + std::to_string(std::llround(period_us)) + " us)");
      }
      loop.phase_ns = static_cast<std::int64_t>(std::llround(phase_us * 1e3));
    }
    if (m.has("overrun")) {
      const std::string o = read_string(f, m.get("overrun"), m.path_of("overrun"));
      if (o != "skip") {
        throw ConfigError(loc_of(f, m.get("overrun")), m.path_of("overrun"),
                          "unknown overrun policy '" + o + "' (only 'skip' is supported)");
      }
    }
    cfg.loops.push_back(std::move(loop));
  }
}

void read_ports(const std::string& f, const MapReader& m, PluginConfig& p) {
  if (!m.has("ports")) return;
  const YAML::Node ports = m.get("ports");
  const std::string path = m.path_of("ports");
  if (!ports.IsMap()) throw ConfigError(loc_of(f, ports), path, "expected a map local: global");
  for (auto it = ports.begin(); it != ports.end(); ++it) {
    const std::string local = read_string(f, it->first, path);
    const std::string kp = path + "." + local;
    if (has_space(local)) throw ConfigError(loc_of(f, it->first), kp, "port names have no spaces");
    if (p.ports.count(local) != 0) {
      throw ConfigError(loc_of(f, it->first), kp, "duplicate port '" + local + "'");
    }
    const std::string global = read_string(f, it->second, kp);
    if (has_space(global)) throw ConfigError(loc_of(f, it->second), kp, "port names have no spaces");
    p.ports.emplace(local, global);
  }
}

// budget: {time_us, cycles}
BudgetConfig read_budget(const MapReader& m) {
  BudgetConfig b;
  b.loc = m.loc();
  if (m.has("time_us")) b.time_us = read_number(m.file(), m.get("time_us"), m.path_of("time_us"), 0.0, 1e7, false);
  if (m.has("cycles")) b.cycles = static_cast<int>(read_int(m.file(), m.get("cycles"), m.path_of("cycles"), 1, 1000000));
  return b;
}

AllocationPolicy read_allocation_policy(const std::string& f, const YAML::Node& node, const std::string& path) {
  const std::string v = read_string(f, node, path);
  if (v == "count") return AllocationPolicy::count;
  if (v == "deactivate") return AllocationPolicy::deactivate;
  throw ConfigError(loc_of(f, node), path, "expected 'count' or 'deactivate', got '" + v + "'");
}

void read_plugins(const MapReader& root, DaemonConfig& cfg) {
  const std::string& f = root.file();
  if (!root.has("plugins")) return;
  const YAML::Node plugins = root.get("plugins");
  if (plugins.IsNull()) return;
  if (!plugins.IsSequence()) {
    throw ConfigError(loc_of(f, plugins), "plugins", "expected a list of plugin instances");
  }
  for (std::size_t i = 0; i < plugins.size(); ++i) {
    const MapReader m(f, plugins[i], index_path("plugins", i),
                      {"name", "library", "loop", "order", "enabled", "params", "ports", "budget",
                       "on_rt_allocation"});
    PluginConfig p;
    p.loc = m.loc();
    p.params_loc = p.loc;
    p.name = read_identifier(f, m.require("name"), m.path_of("name"));
    for (const auto& other : cfg.plugins) {
      if (other.name == p.name) {
        throw ConfigError(loc_of(f, m.get("name")), m.path_of("name"),
                          "duplicate plugin name '" + p.name + "' (first at " +
                              other.loc.str() + ")");
      }
    }
    p.library = read_string(f, m.require("library"), m.path_of("library"));
    if (has_space(p.library)) {
      throw ConfigError(loc_of(f, m.get("library")), m.path_of("library"),
                        "library names have no spaces");
    }
    if (p.library.find('/') != std::string::npos) p.library = resolve(f, p.library);
    const YAML::Node loop_node = m.require("loop");
    p.loop = read_string(f, loop_node, m.path_of("loop"));
    if (cfg.find_loop(p.loop) == nullptr) {
      std::vector<std::string> names;
      for (const auto& l : cfg.loops) names.push_back(l.name);
      std::string reason = "unknown loop '" + p.loop + "'";
      const std::string guess = did_you_mean(p.loop, names);
      if (!guess.empty()) reason += " (did you mean '" + guess + "'?)";
      throw ConfigError(loc_of(f, loop_node), m.path_of("loop"), reason);
    }
    const YAML::Node order_node = m.require("order");
    p.order = static_cast<int>(read_int(f, order_node, m.path_of("order"), -1000000, 1000000));
    for (const auto& other : cfg.plugins) {
      if (other.loop == p.loop && other.order == p.order) {
        throw ConfigError(loc_of(f, order_node), m.path_of("order"),
                          "order " + std::to_string(p.order) + " is already used by '" +
                              other.name + "' in loop '" + p.loop + "'");
      }
    }
    if (m.has("enabled")) p.enabled = read_bool(f, m.get("enabled"), m.path_of("enabled"));
    if (m.has("params")) {
      const YAML::Node params = m.get("params");
      if (params.IsNull()) {
        p.params = YAML::Node(YAML::NodeType::Map);
      } else if (!params.IsMap()) {
        throw ConfigError(loc_of(f, params), m.path_of("params"), "expected a map");
      } else {
        check_no_duplicate_keys(f, params, m.path_of("params"));
        p.params = params;
        p.params_loc = loc_of(f, params);
      }
    } else {
      p.params = YAML::Node(YAML::NodeType::Map);
    }
    read_ports(f, m, p);
    if (m.has("budget")) p.budget = read_budget(MapReader(f, m.get("budget"), m.path_of("budget"), {"time_us", "cycles"}));
    if (m.has("on_rt_allocation")) {
      p.on_rt_allocation = read_allocation_policy(f, m.get("on_rt_allocation"), m.path_of("on_rt_allocation"));
    }
    cfg.plugins.push_back(std::move(p));
  }
}

void read_safety(const MapReader& root, DaemonConfig& cfg) {
  if (!root.has("safety")) return;
  const MapReader m(root.file(), root.get("safety"), "safety", {"on_fault", "max_overruns_per_s", "on_rt_allocation"});
  const std::string& f = m.file();
  cfg.safety.loc = m.loc();
  if (m.has("on_fault")) {
    const std::string v = read_string(f, m.get("on_fault"), m.path_of("on_fault"));
    if (v == "deactivate") {
      cfg.safety.on_fault = FaultPolicy::deactivate;
    } else if (v == "stop") {
      cfg.safety.on_fault = FaultPolicy::stop;
    } else {
      throw ConfigError(loc_of(f, m.get("on_fault")), m.path_of("on_fault"),
                        "expected 'deactivate' or 'stop', got '" + v + "'");
    }
  }
  if (m.has("max_overruns_per_s")) {
    cfg.safety.max_overruns_per_s = read_number(f, m.get("max_overruns_per_s"),
                                                m.path_of("max_overruns_per_s"), 0.0, 1e9, false);
  }
  if (m.has("on_rt_allocation")) {
    cfg.safety.on_rt_allocation = read_allocation_policy(f, m.get("on_rt_allocation"), m.path_of("on_rt_allocation"));
  }
}

}  // namespace

ConfigError error_at(const std::string& file, const YAML::Node& node, const std::string& key_path,
                     const std::string& reason) {
  return ConfigError(loc_of(file, node), key_path, reason);
}

std::int64_t LoopConfig::period_ns() const noexcept {
  return static_cast<std::int64_t>(std::llround(1e9 / rate_hz));
}

const LoopConfig* DaemonConfig::find_loop(const std::string& name) const {
  for (const auto& l : loops) {
    if (l.name == name) return &l;
  }
  return nullptr;
}

const PluginConfig* DaemonConfig::find_plugin(const std::string& name) const {
  for (const auto& p : plugins) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

std::vector<const PluginConfig*> DaemonConfig::plugins_of_loop(const std::string& loop) const {
  std::vector<const PluginConfig*> out;
  for (const auto& p : plugins) {
    if (p.loop == loop) out.push_back(&p);
  }
  std::sort(out.begin(), out.end(),
            [](const PluginConfig* a, const PluginConfig* b) { return a->order < b->order; });
  return out;
}

DaemonConfig load_daemon_config_from_string(const std::string& text,
                                            const std::string& virtual_file,
                                            const LoadOptions& options) {
  const YAML::Node doc = load_bounded_yaml(text, virtual_file, options.bounds);
  if (!doc.IsMap()) {
    SourceLoc loc = loc_of(virtual_file, doc);
    if (loc.line == 0) loc = SourceLoc{virtual_file, 1, 1};
    throw ConfigError(loc, "(document)", "expected a map with plugin_dirs, loops and plugins");
  }
  const MapReader root(virtual_file, doc, "",
                       {"plugin_dirs", "daemon", "loops", "plugins", "safety"});
  DaemonConfig cfg;
  cfg.file = virtual_file;
  read_plugin_dirs(root, options, cfg);
  read_daemon(root, cfg);
  read_loops(root, cfg);
  read_plugins(root, cfg);
  read_safety(root, cfg);
  return cfg;
}

DaemonConfig load_daemon_config(const std::string& path, const LoadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw ConfigError(SourceLoc{path, 0, 0}, "(file)", "cannot read the configuration file");
  }
  // One byte past the limit is enough to refuse it, however large (or endless) the file is.
  std::string text(options.bounds.max_bytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (in.bad()) throw ConfigError(SourceLoc{path, 0, 0}, "(file)", "cannot read the configuration file");
  return load_daemon_config_from_string(text, path, options);
}

const char* to_string(OverrunPolicy p) noexcept {
  switch (p) {
    case OverrunPolicy::skip: return "skip";
  }
  return "?";
}

const char* to_string(FaultPolicy p) noexcept {
  switch (p) {
    case FaultPolicy::deactivate: return "deactivate";
    case FaultPolicy::stop: return "stop";
  }
  return "?";
}

const char* to_string(AllocationPolicy p) noexcept {
  switch (p) {
    case AllocationPolicy::count: return "count";
    case AllocationPolicy::deactivate: return "deactivate";
  }
  return "?";
}

void override_param(DaemonConfig& config, const std::string& assignment) {
  const auto fail = [&](const std::string& why) { throw ConfigError("--set '" + assignment + "': " + why); };
  const std::size_t dot = assignment.find('.'), eq = assignment.find('=');
  if (dot == std::string::npos || eq == std::string::npos || dot == 0 || eq < dot + 2) fail("expected INSTANCE.KEY=VALUE");
  const std::string instance = assignment.substr(0, dot), key = assignment.substr(dot + 1, eq - dot - 1);
  for (PluginConfig& p : config.plugins) {
    if (p.name != instance) continue;
    if (!p.params || p.params.IsNull()) p.params = YAML::Node(YAML::NodeType::Map);
    p.params[key] = YAML::Node(assignment.substr(eq + 1));
    return;
  }
  fail("no plugin instance named '" + instance + "' in " + config.file);
}

}  // namespace crease::config
