#include "drivers/host/tactile_host.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sim_tactile.h"
#include "host_test_support.h"

using namespace crease::drivers;

TEST_CASE("tactile over a pty: start, samples follow contact force, silence is a fault") {
  crease::drivers::testing::ScopedFifo fifo;
  PtyPair pty;
  SerialPort port({pty.slave_path(), 1'000'000, false});
  sim::SimTactile sensor(pty.master_fd());
  sim::DeviceThread dev(pty.master_fd(), [&](std::int64_t t) { sensor.step(t); });
  TactileHost host(port.fd(), {.rate_hz = 500});
  sensor.set_contact_force(1, 2.0f);
  crease::drivers::testing::Ticker tick;
  std::int64_t now = 0;
  // Up to 4 s for the stream to start and 50 samples to arrive (a loaded or sanitized build is slow
  // to start the device thread); the checks below are about content, not start-up time.
  for (int i = 0; i < 4000 && (i < 200 || host.health(now) != LinkHealth::ok || host.samples() <= 50); ++i) {
    host.read_from_rt(now = tick.wait());
  }
  CHECK(sensor.rate_hz() == 500);
  CHECK(host.samples() > 50);
  CHECK(host.health(now) == LinkHealth::ok);
  const auto& s = host.sample();
  CHECK(s.pressure_kpa[1][16] > 15.0f);   // ~20 kPa at the centre for 2 N
  CHECK(s.pressure_kpa[1][0] < s.pressure_kpa[1][16]);
  CHECK(s.pressure_kpa[0][16] == 0.0f);   // no contact on fingertip 0
  sensor.set_silent(true);
  for (int i = 0; i < 40; ++i) host.read_from_rt(now = tick.wait());
  CHECK(host.health(now) == LinkHealth::fault);
  sensor.set_silent(false);
  for (int i = 0; i < 2000 && (i < 40 || host.health(now) != LinkHealth::ok); ++i) host.read_from_rt(now = tick.wait());
  CHECK(host.health(now) == LinkHealth::ok);
}
