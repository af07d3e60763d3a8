// The buses' fault plan (plugins/sim_world/bus_fault_plan.h): the same seed draws the same plan,
// every drawn time lies in the window, the bus-off falls on a hand's bus, the delay burst on any
// of the four, and over many seeds every choice is drawn.
#include "plugins/sim_world/bus_fault_plan.h"

#include <doctest/doctest.h>

#include <set>

using namespace crease::world;

TEST_CASE("a fault plan is its seed's: in the window, on the buses it may fall on, every choice drawn over seeds") {
  BusFaultConfig c;
  c.from_s = 3;
  c.to_s = 9;
  std::set<int> delay_buses, off_buses;
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    c.seed = seed;
    const BusFaultPlan a = draw_bus_faults(c), b = draw_bus_faults(c);
    CHECK(a.delay_bus == b.delay_bus);
    CHECK(a.delay_at_s == b.delay_at_s);
    CHECK(a.bus_off_bus == b.bus_off_bus);
    CHECK(a.bus_off_at_s == b.bus_off_at_s);
    CHECK(a.delay_at_s >= 3.0);
    CHECK(a.delay_at_s <= 9.0);
    CHECK(a.bus_off_at_s >= 3.0);
    CHECK(a.bus_off_at_s <= 9.0);
    CHECK(a.delay_bus >= 0);
    CHECK(a.delay_bus < kFaultBuses);
    CHECK((a.bus_off_bus == 0 || a.bus_off_bus == 1));
    delay_buses.insert(a.delay_bus);
    off_buses.insert(a.bus_off_bus);
  }
  CHECK(delay_buses.size() == 4);
  CHECK(off_buses.size() == 2);
  c.seed = 1;
  const BusFaultPlan p = draw_bus_faults(c);
  c.seed = 2;
  const BusFaultPlan q = draw_bus_faults(c);
  CHECK((p.delay_at_s != q.delay_at_s || p.bus_off_at_s != q.bus_off_at_s));
  const std::string d = describe(p);
  CHECK(d.find(kFaultBusNames[p.delay_bus]) != std::string::npos);
  CHECK(d.find("bus-off") != std::string::npos);
}
