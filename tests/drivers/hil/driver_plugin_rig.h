// Shared fixture of the driver plugin tests (tests/plugins/hand_driver, tests/plugins/arm_driver):
// one driver plugin instance in a 1 kHz "control" loop of a PluginHost, its state port read
// back, and the configuration-error case every CAN driver plugin shares.
#pragma once

#include <doctest/doctest.h>

#include <chrono>
#include <exception>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "core/plugin_host.h"

namespace crease::test {

template <typename State>
class DriverPluginRig {
 public:
  // instance: the instance name; library: the plugin; port: its state output port.
  DriverPluginRig(std::string instance, std::string library, std::string port)
      : host({CREASE_PLUGIN_DIR}), instance_(std::move(instance)), library_(std::move(library)), port_(std::move(port)) {
    host.add_loop({"control", 1000.0, 0, -1});
  }

  [[nodiscard]] InstanceSpec spec(const std::string& yaml) const {
    InstanceSpec s;
    s.name = instance_;
    s.library = library_;
    s.loop = "control";
    s.params = Params(YAML::Load(yaml), "test.yaml", instance_ + ".params");
    return s;
  }
  void add(const std::string& yaml) { host.add_instance(spec(yaml)); }

  // The latest value of the state port.
  [[nodiscard]] State state() {
    State v{};
    const auto* ch = host.ports().find_latest(instance_ + "." + port_);
    if (ch == nullptr) ch = host.ports().find_latest(port_);
    REQUIRE(ch != nullptr);
    ch->read(&v, 0);
    return v;
  }
  // Polls the state until pred holds (at most 3 s): instant checks flake on a loaded machine.
  template <class P>
  State wait_for(P pred) {
    State s = state();
    for (int i = 0; i < 3000 && !pred(s); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      s = state();
    }
    return s;
  }

  // The instance as the host sees it, after draining the loop's events.
  [[nodiscard]] InstanceInfo info() {
    host.poll();
    for (InstanceInfo& i : host.instances()) {
      if (i.name == instance_) return i;
    }
    FAIL("no instance " << instance_);
    return {};
  }
  // Polls the host until pred(info()) holds (at most 3 s).
  template <class P>
  bool wait_host(P pred) {
    for (int i = 0; i < 3000; ++i) {
      if (pred(info())) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return false;
  }

  // The device stops (its thread ends: silence on the bus) and comes back: the host sees a
  // device fault (health fault, counted, the instance still active and scheduled) within the
  // driver's timeout, then its recovery. stop/start: what stops and restarts the device.
  template <class Stop, class Start>
  void check_device_fault_and_recovery(Stop stop, Start start) {
    REQUIRE(wait_host([](const InstanceInfo& i) { return std::string(health_of(i)) == "ok"; }));
    CHECK(host.device_fault_count() == 0);  // start-up before the first answer is no device fault
    stop();
    // The health (the loop's last status) may be seen a moment before the loop's event reaches
    // the host: wait for both.
    CHECK(wait_host([this](const InstanceInfo& i) {
      return std::string(health_of(i)) == "fault" && host.device_fault_count() >= 1;
    }));
    const InstanceInfo gone = info();
    CHECK(gone.state == RunState::active);  // still scheduled: it notices the device's return
    CHECK(gone.stats->device_faults.load() == 1);
    CHECK(gone.stats->faults.load() == 0);  // not a firewall fault
    CHECK(host.device_fault_count() == 1);
    CHECK(host.devices_in_fault() == 1);
    CHECK(host.fault_count() == 0);
    start();
    bool fault_seen = false, recovery_seen = false;
    const auto scan_events = [&] {
      fault_seen = recovery_seen = false;
      for (const HostEvent& e : host.events()) {
        fault_seen |= e.type == HostEvent::Type::device_fault && e.instance == instance_;
        recovery_seen |= e.type == HostEvent::Type::device_recovered && e.instance == instance_ && fault_seen;
      }
      return recovery_seen;
    };
    // As above: the recovery event may reach the host a moment after the health.
    CHECK(wait_host([&](const InstanceInfo& i) { return std::string(health_of(i)) == "ok" && scan_events(); }));
    CHECK(host.devices_in_fault() == 0);
    CHECK(host.device_fault_count() == 1);
    CHECK(fault_seen);
    CHECK(recovery_seen);
  }

  // A bus nobody serves is a configuration error naming the key and the bus.
  void check_unserved_bus_is_config_error() {
    try {
      add("{bus: no-such-bus-crease, node: 1}");
      FAIL("add_instance must throw");
    } catch (const std::exception& e) {
      const std::string what = e.what();
      CHECK(what.find("bus") != std::string::npos);
      CHECK(what.find("no-such-bus-crease") != std::string::npos);
    }
  }

  PluginHost host;

 private:
  std::string instance_, library_, port_;
};

}  // namespace crease::test
