// A driver plugin in a 1 kHz loop (DriverPluginRig) against one simulated device whose bus is
// tapped (CommandTap: what the device receives), with the test as the writer of the driver's
// command port. Shared by the held-command tests of hand_driver and arm_driver.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <thread>

#include "core/port.h"
#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/simdevice/device_thread.h"
#include "rt/clock.h"
#include "tests/drivers/hil/command_tap.h"
#include "tests/drivers/hil/driver_plugin_rig.h"

namespace crease::test {

// Waits (at most 5 s) until pred() holds.
template <class P>
bool eventually(P pred) {
  for (int i = 0; i < 5000 && !pred(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return pred();
}

// Device/DeviceConfig: sim::SimHand or sim::SimArm and its config; WireCommand: the protocol's
// command the tap decodes; PortCommand and State: the driver's command and state payloads.
template <class Device, class DeviceConfig, class WireCommand, class PortCommand, class State>
struct TappedDriverRig {
  using Test = typename drivers::testing::CommandTap<WireCommand>::Test;
  // tag names the bus (made unique per process); the driver is `instance` of `library`.
  TappedDriverRig(const std::string& tag, std::uint8_t node, const char* instance, const char* library,
                  const char* state_port, const char* command_port, Test match, Test zero, Test safe)
      : bus(tag + "-" + std::to_string(::getpid())),
        broker({bus, 1'000'000, 5'000'000, false}),
        dev_bus({bus, node, 1'000'000, 5'000'000}),
        tap(dev_bus, node, match, zero, safe),
        device(tap, config_for(node)),
        thread(dev_bus.fd(), [this](std::int64_t t) { device.step(t); }),
        rig(instance, library, state_port) {
    // timeout_cycles is wide so that a late wake-up of a loaded machine does not put the link
    // into its safe state while frames are counted.
    rig.add("{bus: " + bus + ", node: " + std::to_string(node) + ", timeout_cycles: 100}");
    command = rig.host.ports().bind_latest_writer(command_port, port_type_of<PortCommand>(), "test");
  }
  void write(const PortCommand& c) { command->write(&c, rt::now_ns()); }
  // Starts the loop, waits until ready(driver state) holds, writes `first`, waits until the
  // device received it, then arms the tap (frames from here on are counted).
  template <class Ready>
  void start_with(Ready ready, const PortCommand& first) {
    rig.host.start();
    REQUIRE(eventually([&] { return ready(rig.state()); }));
    write(first);
    REQUIRE(eventually([&] { return tap.matching.load() > 0; }));  // the command reached the device
    tap.arm();
  }

  std::string bus;
  drivers::MockCanBroker broker;
  drivers::MockCanBus dev_bus;
  drivers::testing::CommandTap<WireCommand> tap;
  Device device;
  drivers::sim::DeviceThread thread;
  DriverPluginRig<State> rig;
  rt::LatestChannel* command = nullptr;

 private:
  static DeviceConfig config_for(std::uint8_t node) {
    DeviceConfig c;
    c.node = node;
    return c;
  }
};

}  // namespace crease::test
