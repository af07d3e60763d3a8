// The loop's two phases: update for every instance, then write for those that have one.
#include "core/loop.h"

#include <doctest/doctest.h>

#include <chrono>
#include <thread>

#include "core/plugin_host.h"
#include "plugins/test_plugins/test_ports.h"

using crease::test_plugins::TestValue;
using namespace std::chrono_literals;

namespace {
crease::InstanceSpec spec(const std::string& name, const std::string& lib, int order,
                          std::map<std::string, std::string> ports) {
  crease::InstanceSpec s;
  s.name = name;
  s.library = lib;
  s.loop = "control";
  s.order = order;
  s.params = crease::Params(YAML::Load("{}"), "test.yaml", name + ".params");
  s.ports = std::move(ports);
  return s;
}
}  // namespace

// A driver-like probe (order 10) senses in update and sends in write; a controller (order 20)
// turns the sensing into a command in its update. The command the probe sends in cycle k is
// built from cycle k's sensing: lag 0. Were write called right after the probe's own update
// (no write phase), it would send cycle k-1's command: lag 1.
TEST_CASE("a command computed after the driver's update is sent in the same cycle (write phase)") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, 0, -1});
  host.add_instance(spec("probe", "crease_test_phase_probe", 10, {{"sensed", "sensed"}, {"command", "command"}}));
  host.add_instance(spec("controller", "crease_test_relay", 20, {{"in", "sensed"}, {"out", "command"}}));
  crease::rt::QueueChannel* lags = host.ports().find_queue("lags");
  REQUIRE(lags != nullptr);
  host.start();
  std::uint64_t n = 0, lag0 = 0;
  double worst = 0;
  for (int i = 0; i < 3000 && n < 500; ++i) {
    TestValue v;
    while (lags->try_pop(&v)) {
      ++n;
      lag0 += v.value == 0.0;
      worst = std::max(worst, v.value);
    }
    std::this_thread::sleep_for(1ms);
  }
  host.stop();
  CHECK(n >= 500);
  CHECK(lag0 == n);  // every cycle: the same cycle's sensing (order is deterministic)
  CHECK(worst == 0.0);
}

// Instances without a write hook run as before; the probe's write is timed with its update
// (one execution sample per cycle).
TEST_CASE("an instance with a write phase is counted once per cycle") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, 0, -1});
  host.add_instance(spec("probe", "crease_test_phase_probe", 10, {{"sensed", "s"}, {"command", "c"}}));
  host.add_instance(spec("controller", "crease_test_relay", 20, {{"in", "s"}, {"out", "c"}}));
  host.start();
  auto updates_of = [&](const std::string& name) {
    for (const auto& i : host.instances())
      if (i.name == name) return i.stats->updates.load();
    return std::uint64_t{0};
  };
  for (int i = 0; i < 5000 && updates_of("probe") <= 50; ++i) std::this_thread::sleep_for(1ms);
  host.stop();
  std::uint64_t probe_updates = 0, relay_updates = 0, probe_samples = 0;
  for (const auto& i : host.instances()) {
    if (i.name == "probe") {
      probe_updates = i.stats->updates.load();
      probe_samples = i.stats->execution.snapshot().count;
    }
    if (i.name == "controller") relay_updates = i.stats->updates.load();
  }
  CHECK(probe_updates > 50);
  CHECK(probe_samples == probe_updates);
  CHECK(relay_updates + 2 >= probe_updates);
  CHECK(relay_updates <= probe_updates + 2);
}
