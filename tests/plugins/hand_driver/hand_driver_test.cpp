// The hand_driver plugin in a real 1 kHz loop against a simulated hand on a mock bus.
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <thread>

#include "core/port_types/hand.h"
#include "core/port_types/tactile.h"
#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/host/bus_prefix.h"
#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sense_to_command_tap.h"
#include "drivers/simdevice/sim_hand.h"
#include "drivers/simdevice/sim_tactile.h"
#include "drivers/serial/serial_port.h"
#include "rt/thread_placement.h"
#include "rt/alloc_guard.h"
#include "rt/clock.h"
#include "tests/drivers/hil/tapped_driver_rig.h"
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
  // The path carries the commands: a fresh status (health ok) answers the last SYNC and echoes
  // the command sent with it. How many answers came two cycles late (commands_failed) is a
  // figure of the machine's load (crease-bench bus), not a behaviour: never compared here.
  CHECK(s.acked_seq == static_cast<std::uint16_t>(s.commands_sent));
  CHECK(s.commands_failed <= s.commands_sent);
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

// With the driver reporting a fault link as Status::degraded (as it did), the host counted no
// device fault and showed the instance healthy: the checks of device_faults and health fail.
TEST_CASE("hand_driver: a stopped hand is a device fault in the host, and recovers when it runs again") {
  const std::string bus = "plug-hand-gone-" + std::to_string(::getpid());
  dr::MockCanBroker broker({bus, 1'000'000, 5'000'000, false});
  dr::MockCanBus dev_bus({bus, 1, 1'000'000, 5'000'000});
  dr::sim::SimHand hand(dev_bus, {.node = 1});
  std::optional<dr::sim::DeviceThread> dev;
  dev.emplace(dev_bus.fd(), [&](std::int64_t t) { hand.step(t); });
  Rig rig("hand_r", "hand_driver", "hand_state");
  rig.add("{bus: " + bus + ", node: 1}");
  rig.host.start();
  rig.check_device_fault_and_recovery([&] { dev.reset(); },
                                      [&] { dev.emplace(dev_bus.fd(), [&](std::int64_t t) { hand.step(t); }); });
  // The port shows it too (waited for: on a loaded machine one late answer reads degraded).
  CHECK(rig.wait_for([](const HandState& v) { return v.health == DeviceHealth::ok; }).health == DeviceHealth::ok);
  rig.host.stop();
}

TEST_CASE("hand_driver: a bus nobody serves is a configuration error naming the key") {
  Rig("hand_r", "hand_driver", "hand_state").check_unserved_bus_is_config_error();
}

TEST_CASE("hand_driver: a bare tactile_device name is a simulated robot's link and needs bus_prefix") {
  Rig rig("hand_r", "hand_driver", "hand_state");
  const std::string prefix = "crease-t-hdtl-" + std::to_string(::getpid());
  dr::MockCanBroker broker({prefix + "-hand_r", 1'000'000, 5'000'000, false});
  const auto error_of = [&](const std::string& yaml) -> std::string {
    try {
      rig.add(yaml);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string bare = error_of("{bus: " + prefix + "-hand_r, node: 1, tactile_device: tactile_r}");
  CHECK(bare.find("test.yaml") != std::string::npos);
  CHECK(bare.find("tactile_device: a bare name is a simulated robot's link and needs bus_prefix") != std::string::npos);
  // With the prefix: the link <runtime dir>/<prefix>-tactile_r, which no world has made here.
  const std::string missing = error_of("{bus_prefix: " + prefix + ", bus: hand_r, node: 1, tactile_device: tactile_r}");
  CHECK(missing.find("tactile_device") != std::string::npos);
  CHECK(missing.find(dr::simulated_link_path(prefix, "tactile_r")) != std::string::npos);
}

namespace {
// The command the test writes: every joint a distinct, non-zero target.
float target_of(int j, float offset) { return 0.1f + offset + 0.01f * static_cast<float>(j); }
bool matches_held(const dr::hand::Command& c) {
  if (!(c.flags & dr::hand::kCmdEnable)) return false;
  for (int j = 0; j < dr::hand::kJoints; ++j)
    if (std::fabs(c.target_rad[j] - target_of(j, 0.0f)) > 1e-3f) return false;
  return true;
}
bool all_zero(const dr::hand::Command& c) {
  for (float t : c.target_rad)
    if (std::fabs(t) > 1e-4f) return false;
  return true;
}
// A frame of the driver's safe state: the hand disabled (hold position, zero force), sent when
// the link's watchdog tripped on a stalled machine.
bool safe_frame(const dr::hand::Command& c) { return (c.flags & dr::hand::kCmdEnable) == 0; }
HandCommand command_with(float offset) {
  HandCommand c;
  c.enable = 1;
  for (int j = 0; j < HandCommand::kJoints; ++j) {
    c.target_rad[j] = target_of(j, offset);
    c.stiffness_nm_per_rad[j] = 2.0f;
  }
  return c;
}
using HoldRig = test::TappedDriverRig<dr::sim::SimHand, dr::sim::SimHandConfig, dr::hand::Command, HandCommand, HandState>;
using test::eventually;
bool link_ok(const HandState& s) { return s.health == DeviceHealth::ok; }
}  // namespace

// The device side sees every command frame: a command written once must be the command of
// every cycle after it (the driver must not fall back to a default, all-zero command on the
// cycles when nothing new arrived).
TEST_CASE("hand_driver: a command written once is held unchanged, frame after frame, for 1000 cycles") {
  HoldRig r("plug-hand-hold", 1, "hand_r", "hand_driver", "hand_state", "hand_command", &matches_held, &all_zero, &safe_frame);
  auto& tap = r.tap;
  r.start_with(&link_ok, command_with(0.0f));
  const auto start = tap.matching.load();
  // 1000 commanding frames (safe-state frames of a stalled machine are counted apart).
  REQUIRE(eventually([&] { return tap.matching.load() >= start + 1000; }));
  r.rig.host.stop();
  CHECK(tap.matching.load() >= 1000);
  CHECK(tap.differing.load() == 0);
  CHECK(tap.zeros.load() == 0);
  // Safe-state frames (the link faulted on a stalled machine) are a figure of the machine's
  // load, not compared: a broken hold shows as differing or zero frames, or never 1000 matching.
  MESSAGE("safe-state frames " << tap.safe.load() << " beside " << tap.matching.load()
                               << " matching");
}

// A 60 Hz writer (the model loop's rate) feeding the 1 kHz driver: ~16 driver cycles per
// command; none of them may send a zero command once the first command arrived.
TEST_CASE("hand_driver: a 60 Hz command writer never produces a zero command frame at 1 kHz") {
  HoldRig r("plug-hand-60", 1, "hand_r", "hand_driver", "hand_state", "hand_command", &matches_held, &all_zero, &safe_frame);
  auto& tap = r.tap;
  r.start_with(&link_ok, command_with(0.0f));
  // Paced by the frames the device sees, not by the wall clock (a loaded machine stretches
  // both alike): a new command every 16 driver cycles, as 60 Hz against 1 kHz.
  const auto frames_before = tap.total.load();
  for (int i = 1; i <= 60; ++i) {
    REQUIRE(eventually([&] { return tap.total.load() >= frames_before + 16u * static_cast<unsigned>(i); }));
    r.write(command_with(0.05f * std::sin(0.3f * static_cast<float>(i))));
  }
  r.rig.host.stop();
  CHECK(tap.total.load() - frames_before >= 960);
  CHECK(tap.zeros.load() == 0);
}

// The write phase seen from the hand: a controller that runs after the driver (hand_echo, order
// 20) builds each command from the status the driver read in that cycle, and the driver sends
// it in the same cycle: the command the hand receives answers the newest status it sent (lag
// 0). Without a write phase the driver would send in its update, before the controller ran:
// lag 1 at best: the device has answered the next SYNC before that command reaches it, so lag 0
// cannot occur at all. A late wake-up of a loaded machine makes cycles lag (on a quiet machine
// most are lag 0; that share is the machine's figure, not compared): lag 0 must occur.
TEST_CASE("hand_driver: a status received in cycle k is answered by a command built from it in cycle k") {
  const std::string bus = "plug-hand-lag-" + std::to_string(::getpid());
  dr::MockCanBroker broker({bus, 1'000'000, 5'000'000, false});
  dr::MockCanBus dev_bus({bus, 1, 1'000'000, 5'000'000});
  dr::sim::SenseToCommandTap tap(dev_bus, 1);
  dr::sim::SimHand hand(tap, {.node = 1});
  dr::sim::DeviceThread dev(dev_bus.fd(), [&](std::int64_t t) { hand.step(t); });

  Rig rig("hand_r", "hand_driver", "hand_state");
  rig.add("{bus: " + bus + ", node: 1, timeout_cycles: 100}");
  InstanceSpec echo;
  echo.name = "echo";
  echo.library = "crease_test_hand_echo";
  echo.loop = "control";
  echo.order = 20;
  rig.host.add_instance(echo);
  rig.host.start();
  auto counted = [&] {
    std::uint64_t n = 0;
    for (int k = 0; k < dr::sim::SenseToCommandTap::kLags; ++k) n += tap.commands_with_lag(k);
    return n;
  };
  REQUIRE(eventually([&] { return counted() >= 1000; }));
  rig.host.stop();
  MESSAGE("lag 0: " << tap.commands_with_lag(0) << ", 1: " << tap.commands_with_lag(1) << ", 2: "
                    << tap.commands_with_lag(2) << ", more: " << tap.commands_with_lag(3));
  CHECK(tap.commands_with_lag(0) >= 10);
}

namespace {
// The hand of the first test with a tactile link on a pty: `tactile_device` is its slave.
struct TactileRig {
  std::string bus = "plug-hand-tac-" + std::to_string(::getpid());
  dr::MockCanBroker broker{{bus, 1'000'000, 5'000'000, false}};
  dr::MockCanBus dev_bus{{bus, 1, 1'000'000, 5'000'000}};
  dr::sim::SimHand hand{dev_bus, {.node = 1}};
  dr::sim::DeviceThread dev{dev_bus.fd(), [this](std::int64_t t) { hand.step(t); }};
  dr::PtyPair pty;
  Rig rig{"hand_r", "hand_driver", "hand_state"};
  TactileRig() { rig.add("{bus: " + bus + ", node: 1, tactile_device: " + pty.slave_path() + "}"); }
  Tactile tactile() {
    Tactile v{};
    const auto* ch = rig.host.ports().find_latest("tactile");
    REQUIRE(ch != nullptr);
    ch->read(&v, 0);
    return v;
  }
};
}  // namespace

// Nobody answers on the tactile link (the pty's master is never read or written): the link's
// thread waits in its read, the loop runs on and reports the link as faulted.
TEST_CASE("hand_driver: a tactile link nobody serves does not hold up the loop; its reader is a named thread below the loop") {
  TactileRig t;
  t.rig.host.start();
  HandState s = t.rig.wait_for([](const HandState& v) { return v.health == DeviceHealth::ok && v.commands_sent > 500; });
  CHECK(s.commands_sent > 500);  // cycles went on
  const Tactile tac = t.tactile();
  CHECK(tac.health == DeviceHealth::fault);
  CHECK(tac.frames == 0);
  const auto allocs = rt::rt_allocation_count();
  const auto sent = t.rig.state().commands_sent;
  REQUIRE(eventually([&] { return t.rig.state().commands_sent > sent + 200; }));
  CHECK(rt::rt_allocation_count() == allocs);
  bool found = false;
  for (const rt::ThreadInfo& th : rt::list_threads()) {
    if (th.name != "crease-tactile") continue;
    found = true;
    // Not the loop's SCHED_FIFO (where the test may grant it): its own tactile_priority (1) where
    // the process may take it, else the default policy.
    CHECK(((th.policy == "fifo" && th.priority == 1) || th.policy == "other"));
  }
  CHECK(found);
  // The Start it sent is waiting in the pty for a sensor.
  std::uint8_t buf[64];
  CHECK(::read(t.pty.master_fd(), buf, sizeof buf) > 0);
  t.rig.host.stop();
  for (const rt::ThreadInfo& th : rt::list_threads()) CHECK(th.name != "crease-tactile");  // stopped with the instance
}

// The sensor at its default 250 Hz on the pty: the port's samples come in order, and every
// sample the sensor put on the link whole was taken by the loop or counted as an overrun. (A
// sample the pty did not take whole, when its kernel side fell behind, is the link's loss, not
// the reader's: SimTactile counts only the samples it wrote whole.)
TEST_CASE("hand_driver: tactile samples at the sensor's rate reach the port in order, none lost") {
  TactileRig t;
  dr::sim::SimTactile sensor(t.pty.master_fd());
  dr::sim::DeviceThread sdev(t.pty.master_fd(), [&](std::int64_t now) { sensor.step(now); });
  sensor.set_contact_force(2, 1.0f);
  t.rig.host.start();
  REQUIRE(eventually([&] { return t.tactile().frames > 0; }));
  const Tactile first = t.tactile();
  Tactile last = first;
  std::uint64_t out_of_order = 0;
  REQUIRE(eventually([&] {
    const Tactile v = t.tactile();
    if (static_cast<std::int16_t>(v.sample_counter - last.sample_counter) < 0 || v.frames < last.frames) ++out_of_order;
    last = v;
    return v.frames >= first.frames + 500;
  }));
  CHECK(out_of_order == 0);
  CHECK(last.health == DeviceHealth::ok);
  CHECK(last.pressure_kpa[2][16] > 5.0f);  // ~10 kPa at the centre for 1 N
  CHECK(last.pressure_kpa[0][16] == 0.0f);
  // The sensor falls silent; once the loop has taken what was on the link, every sample it
  // sent is accounted for.
  sensor.set_silent(true);
  const auto accounted = [&] {
    const Tactile v = t.tactile();
    return v.frames + v.overruns == sensor.samples_sent();
  };
  CHECK(eventually(accounted));
  const Tactile end = t.tactile();
  t.rig.host.stop();
  MESSAGE("samples sent " << sensor.samples_sent() << ", taken " << end.frames << ", overruns " << end.overruns
                          << ", CRC errors " << end.crc_errors);
  CHECK(end.frames + end.overruns == sensor.samples_sent());
}

// The tactile sensor falls silent while the hand goes on answering: once its samples have been
// stale for device_fault_cycles the instance reports a device fault (counted by the host,
// health fault, still scheduled), and recovers when the sensor streams again. With the tactile
// link reported as Status::degraded only (as it was), the host counted no device fault: the
// rig's checks of device_faults and health fail.
TEST_CASE("hand_driver: a silent tactile sensor is a device fault in the host, and recovers when it streams again") {
  TactileRig t;
  dr::sim::SimTactile sensor(t.pty.master_fd());
  dr::sim::DeviceThread sdev(t.pty.master_fd(), [&](std::int64_t now) { sensor.step(now); });
  t.rig.host.start();
  REQUIRE(eventually([&] { return t.tactile().health == DeviceHealth::ok; }));
  t.rig.check_device_fault_and_recovery([&] { sensor.set_silent(true); }, [&] { sensor.set_silent(false); });
  CHECK(t.rig.wait_for(link_ok).health == DeviceHealth::ok);  // the hand's own link is sound
  CHECK(eventually([&] { return t.tactile().health == DeviceHealth::ok; }));
  t.rig.host.stop();
}
