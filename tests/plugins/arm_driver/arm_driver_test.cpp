// The arm_driver plugin in a real 1 kHz loop against a simulated arm on a mock bus.
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include "core/port_types/arm.h"
#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sim_arm.h"
#include "rt/alloc_guard.h"
#include "tests/drivers/hil/driver_plugin_rig.h"

using namespace crease;
namespace dr = crease::drivers;

using Rig = test::DriverPluginRig<ArmState>;

TEST_CASE("arm_driver: enables the drive, fresh state, no allocation, quick stop on silence, recovery") {
  const std::string bus = "plug-arm-" + std::to_string(::getpid());
  dr::MockCanBroker broker({bus, 1'000'000, 5'000'000, false});
  dr::MockCanBus dev_bus({bus, 10, 1'000'000, 5'000'000});
  dr::sim::SimArm arm_dev(dev_bus, {.node = 10});
  dr::sim::DeviceThread dev(dev_bus.fd(), [&](std::int64_t t) { arm_dev.step(t); });

  Rig rig("arm_r", "arm_driver", "arm_state");
  rig.add("{bus: " + bus + ", node: 10}");
  rig.host.start();
  ArmState s = rig.wait_for([](const ArmState& v) { return v.health == DeviceHealth::ok && v.commands_sent > 200; });
  CHECK(s.health == DeviceHealth::ok);
  CHECK(s.commands_sent > 200);
  CHECK(s.commands_failed * 4 < s.commands_sent);
  CHECK(s.drive_state == 4);  // cia402::State::operation_enabled, reached by the driver itself

  const auto allocs = rt::rt_allocation_count();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  CHECK(rt::rt_allocation_count() == allocs);  // the loop thread is RT-marked

  arm_dev.set_silent(true);
  s = rig.wait_for([](const ArmState& v) { return v.health == DeviceHealth::fault; });
  CHECK(s.health == DeviceHealth::fault);
  CHECK(s.fresh == 0);
  CHECK(s.safe_state == 1);
  arm_dev.set_silent(false);
  s = rig.wait_for([](const ArmState& v) { return v.health == DeviceHealth::ok; });
  CHECK(s.health == DeviceHealth::ok);  // re-enabled by the driver after the drive's quick stop
  CHECK(s.fresh == 1);
  rig.host.stop();
}

TEST_CASE("arm_driver: a bus nobody serves is a configuration error naming the key") {
  Rig("arm_r", "arm_driver", "arm_state").check_unserved_bus_is_config_error();
}
