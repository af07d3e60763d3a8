// A daemon-like host for the dds_bridge tests: one loop, plugins added from YAML, ports and the
// bridge's counters read from the test thread. Every bridge of one test process uses the domain
// and topic prefix of that process, so test runs in parallel never hear each other.
#pragma once

#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "core/plugin_host.h"
#include "core/port_types/bridge_stats.h"

namespace crease::test {

// 1..200, from the process id: the DDS domain of this test process.
inline int test_domain() { return 1 + static_cast<int>(::getpid() % 200); }
// A topic name of this test process: "t<pid>/<name>".
inline std::string test_topic(const std::string& name) { return "t" + std::to_string(::getpid()) + "/" + name; }
// A bridge's params in this process's domain with LINKS ("publish: [...]", "subscribe: [...]").
inline std::string bridge_params(const std::string& links) {
  return "{domain: " + std::to_string(test_domain()) + ", " + links + "}";
}

struct BridgeHost {
  PluginHost host{{CREASE_PLUGIN_DIR}};
  explicit BridgeHost(double rate_hz = 1000.0) { host.add_loop({"control", rate_hz, 0, -1}); }
  // Relative paths in params resolve against config/ (dds/loopback.xml is the default XML).
  void add(const std::string& name, const std::string& library, int order, const std::string& yaml) {
    InstanceSpec s;
    s.name = name;
    s.library = library;
    s.loop = "control";
    s.order = order;
    s.params = Params(YAML::Load(yaml), std::string(CREASE_SOURCE_DIR) + "/config/test.yaml", name + ".params");
    host.add_instance(s);
  }
  template <class T>
  rt::ReadInfo read(const std::string& port, T& out) const {
    const auto* ch = const_cast<PluginHost&>(host).ports().find_latest(port);
    REQUIRE(ch != nullptr);
    return ch->read(&out, 0);
  }
  BridgeStats stats(const std::string& bridge) const {
    BridgeStats s;
    (void)read(bridge + "_stats", s);
    return s;
  }
  std::uint64_t degraded(const std::string& name) const {
    for (const auto& i : host.instances())
      if (i.name == name) return i.stats->degraded.load();
    return 0;
  }
  std::uint64_t updates(const std::string& name) const {
    for (const auto& i : host.instances())
      if (i.name == name) return i.stats->updates.load();
    return 0;
  }
  RunState state(const std::string& name) const {
    for (const auto& i : host.instances())
      if (i.name == name) return i.state;
    return RunState::inactive;
  }
};

// Polls `pred` every 5 ms for up to 20 s (a bound for a loaded machine, not a figure).
template <class P>
bool eventually(P pred) {
  for (int i = 0; i < 4000; ++i) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

}  // namespace crease::test
