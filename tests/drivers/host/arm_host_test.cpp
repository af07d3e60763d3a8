#include "drivers/host/arm_host.h"

#include <doctest/doctest.h>

#include <cmath>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sim_arm.h"
#include "host_test_support.h"

using namespace crease::drivers;
using crease::drivers::testing::Ticker;

namespace {
void run(ArmHost& host, const arm::Command& cmd, Ticker& tick, int cycles) {
  for (int i = 0; i < cycles; ++i) {
    const auto now = tick.wait();
    host.read_from_rt(now);
    host.write_from_rt(cmd, now);
  }
}
// Runs until the link is ok and the drive enabled (at most max_cycles); false if it never was.
// (A single-instant check would flake when a loaded machine delays a cycle by > 2 ms.)
bool run_until_enabled(ArmHost& host, const arm::Command& cmd, Ticker& tick, int max_cycles) {
  for (int i = 0; i < max_cycles; ++i) {
    run(host, cmd, tick, 1);
    if (host.health() == LinkHealth::ok && host.reading().drive == cia402::State::operation_enabled) return true;
  }
  return false;
}
}  // namespace

TEST_CASE("the host enables the drive, tracks set points, resets a fault once it clears") {
  crease::drivers::testing::ScopedFifo fifo;
  const std::string name = crease::drivers::testing::unique_bus("arm");
  MockCanBroker broker({name, 1'000'000, 5'000'000, false});
  MockCanBus host_bus({name, 100, 1'000'000, 5'000'000});
  MockCanBus dev_bus({name, 10, 1'000'000, 5'000'000});
  sim::SimArm arm_dev(dev_bus, {.node = 10});
  sim::DeviceThread dev(dev_bus.fd(), [&](std::int64_t t) { arm_dev.step(t); });
  ArmHost host(host_bus, {.node = 10});
  arm::Command cmd;
  for (int j = 0; j < arm::kJoints; ++j) cmd.position_rad[j] = 0.1f * static_cast<float>(j + 1);
  Ticker tick;
  REQUIRE(run_until_enabled(host, cmd, tick, 1000));
  run(host, cmd, tick, 300);
  CHECK(std::abs(host.reading().status.position_rad[6] - 0.7f) < 0.01f);
  // The drive echoes the seq of the commands it applied (acknowledgements reach the monitor).
  CHECK(host.monitor().counters().commands_acked > 0);
  CHECK(host.monitor().last_acked_seq() != 0);

  arm_dev.set_fault(true);
  run(host, cmd, tick, 5);
  CHECK(host.health() == LinkHealth::fault);
  CHECK(host.commanding_safe_state());
  run(host, cmd, tick, 50);
  CHECK(arm_dev.drive_state() == cia402::State::fault);  // resets fail while the cause persists
  arm_dev.set_fault(false);
  CHECK(run_until_enabled(host, cmd, tick, 1000));

  // Silence: quick stop within 3 cycles; the drive's own watchdog quick-stops it as well.
  arm_dev.set_silent(true);
  int to_safe = -1;
  for (int i = 0; i < 10; ++i) {
    run(host, cmd, tick, 1);
    if (to_safe < 0 && host.commanding_safe_state()) to_safe = i + 1;
  }
  CHECK(to_safe >= 1);
  CHECK(to_safe <= 3);
  CHECK(host.last_controlword() == cia402::kCmdQuickStop);
  CHECK(arm_dev.drive_state() == cia402::State::quick_stop_active);
  arm_dev.set_silent(false);
  CHECK(run_until_enabled(host, cmd, tick, 1000));
}
