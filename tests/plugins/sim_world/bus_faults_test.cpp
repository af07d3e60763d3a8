// The buses' fault injector (plugins/sim_world/bus_faults.h) on the simulated robot's buses, a
// driver's node (100) and a listener on the right hand's bus: nothing happens before its world
// time; the delay burst delivers every frame late for its length, then on time again; the
// bus-off puts the driver's node into bus-off at its time.
#include "plugins/sim_world/bus_faults.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include "rt/clock.h"
#include "tests/drivers/can/mock_bus_test_support.h"

using namespace crease;
using namespace crease::drivers;
using namespace crease::drivers::testing;

namespace {

// Waits up to 2 s for PRED (the injector's thread polls every 2 ms).
template <class F>
bool eventually(F pred) {
  for (int i = 0; i < 1000; ++i) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return pred();
}

// Wall time (ms) from FROM's send to TO's reception of one frame; -1 if none came within 1 s.
double latency_ms(CanBus& from, CanBus& to, std::uint32_t id) {
  const std::int64_t t0 = rt::now_ns();
  REQUIRE(from.send(frame_with_id(id)) == SendResult::ok);
  RxFrame rx;
  if (recv_wait(to, rx) != RecvResult::frame) return -1;
  CHECK(rx.frame.id() == id);
  return static_cast<double>(rt::now_ns() - t0) * 1e-6;
}

}  // namespace

TEST_CASE("bus faults come at their world time: a delay burst on the hand's bus, then the driver's bus-off") {
  sim::SimRobotConfig rc;
  rc.prefix = "crease-t-bf-" + std::to_string(::getpid());
  sim::SimRobot robot(rc);
  MockCanBus host(node(rc.prefix + "-hand_r", 100)), peer(node(rc.prefix + "-hand_r", 101));
  REQUIRE(eventually([&] { return robot.broker(0).connected_nodes() >= 3; }));

  world::BusFaultConfig c;
  c.drop = c.corrupt = 0;
  c.delay_ms = 40;
  c.delay_burst_s = 0.5;
  world::BusFaultPlan plan = world::draw_bus_faults(c);
  plan.delay_bus = 0;
  plan.delay_at_s = 1.0;
  plan.bus_off_bus = 0;
  plan.bus_off_at_s = 2.0;
  world::BusFaultInjector inj(robot, plan);

  inj.tick_rt(0.9);  // before anything is due
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  CHECK(inj.counts().delay_bursts_started == 0);
  CHECK(latency_ms(host, peer, 1) < 30.0);

  inj.tick_rt(1.1);  // the burst
  REQUIRE(eventually([&] { return inj.counts().delay_bursts_started == 1; }));
  CHECK(latency_ms(host, peer, 2) >= 35.0);
  CHECK(host.state() == BusState::error_active);

  inj.tick_rt(1.6);  // its end
  REQUIRE(eventually([&] { return inj.counts().delay_bursts_ended == 1; }));
  RxFrame rx;
  while (recv_wait(peer, rx, 60) == RecvResult::frame) {
  }
  CHECK(latency_ms(host, peer, 3) < 30.0);
  CHECK(inj.counts().bus_offs == 0);

  inj.tick_rt(2.05);  // the driver's bus-off
  REQUIRE(eventually([&] { return inj.counts().bus_offs == 1; }));
  REQUIRE(recv_wait(host, rx) == RecvResult::error_frame);
  CHECK(host.state() == BusState::bus_off);
  CHECK(host.send(frame_with_id(4)) == SendResult::bus_off);
}
