// The hand_driver plugin in a real 1 kHz loop against a simulated hand on a mock bus.
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include "core/port_types/hand.h"
#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sim_hand.h"
#include "rt/alloc_guard.h"
#include "tests/drivers/hil/driver_plugin_rig.h"

using namespace crease;
namespace dr = crease::drivers;

using Rig = test::DriverPluginRig<HandState>;

TEST_CASE("hand_driver: fresh state, no allocation, safe within 3 cycles of silence, recovery") {
  const std::string bus = "plug-hand-" + std::to_string(::getpid());
  dr::MockCanBroker broker({bus, 1'000'000, 5'000'000, false});
  dr::MockCanBus dev_bus({bus, 1, 1'000'000, 5'000'000});
  dr::sim::SimHand hand(dev_bus, {.node = 1});
  dr::sim::DeviceThread dev(dev_bus.fd(), [&](std::int64_t t) { hand.step(t); });

  Rig rig("hand_r", "hand_driver", "hand_state");
  rig.add("{bus: " + bus + ", node: 1}");
  rig.host.start();
  HandState s = rig.wait_for([](const HandState& v) { return v.health == DeviceHealth::ok && v.commands_sent > 200; });
  CHECK(s.health == DeviceHealth::ok);
  CHECK(s.commands_sent > 200);
  CHECK(s.commands_failed * 4 < s.commands_sent);
  CHECK(s.safe_state == 1);  // no hand_command yet: it holds

  const auto allocs = rt::rt_allocation_count();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  CHECK(rt::rt_allocation_count() == allocs);  // the loop thread is RT-marked

  hand.set_silent(true);
  s = rig.wait_for([](const HandState& v) { return v.health == DeviceHealth::fault; });
  CHECK(s.health == DeviceHealth::fault);
  CHECK(s.fresh == 0);
  hand.set_silent(false);
  s = rig.wait_for([](const HandState& v) { return v.health == DeviceHealth::ok; });
  CHECK(s.health == DeviceHealth::ok);
  CHECK(s.fresh == 1);
  rig.host.stop();
}

TEST_CASE("hand_driver: a bus nobody serves is a configuration error naming the key") {
  Rig("hand_r", "hand_driver", "hand_state").check_unserved_bus_is_config_error();
}
