// What a driver plugin reports to the host for its link's health: a device fault only for a
// fault that lasted device_fault_cycles after start-up; shorter faults, degraded links and the
// start-up before first contact are degraded.
#include "drivers/host/device_port_glue.h"

#include <doctest/doctest.h>

using crease::Status;
using crease::drivers::DeviceFaultReport;
using crease::drivers::LinkHealth;
using crease::drivers::LinkMonitor;
using crease::drivers::LinkMonitorConfig;

TEST_CASE("a fault lasting device_fault_cycles is a device fault; a shorter one is degraded; ok recovers") {
  LinkMonitorConfig cfg;
  cfg.first_contact_cycles = 0;  // past start-up from the first cycle
  const LinkMonitor monitor(cfg);
  REQUIRE(monitor.past_start_up());
  DeviceFaultReport report(5);
  CHECK(report.update(LinkHealth::ok, monitor) == Status::ok);
  for (int i = 1; i < 5; ++i) CHECK(report.update(LinkHealth::fault, monitor) == Status::degraded);
  CHECK(report.update(LinkHealth::fault, monitor) == Status::device_fault);  // the 5th in a row
  CHECK(report.status() == Status::device_fault);
  CHECK(report.update(LinkHealth::fault, monitor) == Status::device_fault);
  CHECK(report.update(LinkHealth::degraded, monitor) == Status::degraded);  // answered again
  CHECK(report.update(LinkHealth::fault, monitor) == Status::degraded);     // the run starts over
  CHECK(report.update(LinkHealth::ok, monitor) == Status::ok);
}

TEST_CASE("before the device first answered, a silent link is degraded, not a device fault") {
  LinkMonitorConfig cfg;
  cfg.first_contact_cycles = 1000;
  const LinkMonitor monitor(cfg);  // no cycle run, never answered
  REQUIRE_FALSE(monitor.past_start_up());
  DeviceFaultReport report(1);
  for (int i = 0; i < 10; ++i) CHECK(report.update(LinkHealth::fault, monitor) == Status::degraded);
}

TEST_CASE("a link that never answers within first_contact_cycles is past start-up") {
  LinkMonitorConfig cfg;
  cfg.first_contact_cycles = 3;
  LinkMonitor monitor(cfg);
  for (int i = 0; i < 3; ++i) {
    CHECK_FALSE(monitor.past_start_up());
    monitor.begin_read();
    monitor.end_read(false);
  }
  CHECK(monitor.past_start_up());
  CHECK(monitor.health() == LinkHealth::fault);
}
