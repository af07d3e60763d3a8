// The hand_driver plugin in a real 1 kHz loop against a simulated hand on a mock bus.
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include "core/plugin_host.h"
#include "core/port_types/hand.h"
#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sim_hand.h"
#include "rt/alloc_guard.h"

using namespace crease;
namespace dr = crease::drivers;

namespace {
InstanceSpec spec(const std::string& yaml) {
  InstanceSpec s;
  s.name = "hand_r";
  s.library = "hand_driver";
  s.loop = "control";
  s.params = Params(YAML::Load(yaml), "test.yaml", "hand_r.params");
  return s;
}
HandState state_of(PluginHost& host) {
  HandState v{};
  const auto* ch = host.ports().find_latest("hand_r.hand_state");
  if (ch == nullptr) ch = host.ports().find_latest("hand_state");
  REQUIRE(ch != nullptr);
  ch->read(&v, 0);
  return v;
}
// Polls the state until pred holds (at most 3 s): instant checks flake on a loaded machine.
template <class P>
HandState wait_for(PluginHost& host, P pred) {
  HandState s = state_of(host);
  for (int i = 0; i < 3000 && !pred(s); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    s = state_of(host);
  }
  return s;
}
}  // namespace

TEST_CASE("hand_driver: fresh state, no allocation, safe within 3 cycles of silence, recovery") {
  const std::string bus = "plug-hand-" + std::to_string(::getpid());
  dr::MockCanBroker broker({bus, 1'000'000, 5'000'000, false});
  dr::MockCanBus dev_bus({bus, 1, 1'000'000, 5'000'000});
  dr::sim::SimHand hand(dev_bus, {.node = 1});
  dr::sim::DeviceThread dev(dev_bus.fd(), [&](std::int64_t t) { hand.step(t); });

  PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, 0, -1});
  host.add_instance(spec("{bus: " + bus + ", node: 1}"));
  host.start();
  HandState s = wait_for(host, [](const HandState& v) { return v.health == DeviceHealth::ok && v.commands_sent > 200; });
  CHECK(s.health == DeviceHealth::ok);
  CHECK(s.commands_sent > 200);
  CHECK(s.commands_failed * 4 < s.commands_sent);
  CHECK(s.safe_state == 1);  // no hand_command yet: it holds

  const auto allocs = rt::rt_allocation_count();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  CHECK(rt::rt_allocation_count() == allocs);  // the loop thread is RT-marked

  hand.set_silent(true);
  s = wait_for(host, [](const HandState& v) { return v.health == DeviceHealth::fault; });
  CHECK(s.health == DeviceHealth::fault);
  CHECK(s.fresh == 0);
  hand.set_silent(false);
  s = wait_for(host, [](const HandState& v) { return v.health == DeviceHealth::ok; });
  CHECK(s.health == DeviceHealth::ok);
  CHECK(s.fresh == 1);
  host.stop();
}

TEST_CASE("hand_driver: a bus nobody serves is a configuration error naming the key") {
  PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, 0, -1});
  try {
    host.add_instance(spec("{bus: no-such-bus-crease, node: 1}"));
    FAIL("add_instance must throw");
  } catch (const std::exception& e) {
    const std::string what = e.what();
    CHECK(what.find("bus") != std::string::npos);
    CHECK(what.find("no-such-bus-crease") != std::string::npos);
  }
}
