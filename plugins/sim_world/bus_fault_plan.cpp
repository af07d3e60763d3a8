#include "plugins/sim_world/bus_fault_plan.h"

#include <cstdio>
#include <random>

namespace crease::world {

BusFaultPlan draw_bus_faults(const BusFaultConfig& cfg) {
  BusFaultPlan p;
  p.cfg = cfg;
  std::mt19937_64 rng(cfg.seed * 0x9E3779B97F4A7C15ull + 0xB5);
  std::uniform_real_distribution<double> when(cfg.from_s, cfg.to_s);
  std::uniform_int_distribution<int> any_bus(0, kFaultBuses - 1), hand(0, 1);
  p.delay_bus = any_bus(rng);
  p.delay_at_s = when(rng);
  p.bus_off_bus = hand(rng);
  p.bus_off_at_s = when(rng);
  return p;
}

std::string describe(const BusFaultPlan& p) {
  char buf[320];
  int n = std::snprintf(buf, sizeof buf, "bus faults (seed %llu): drop %g, corrupt %g per frame on every bus",
                        static_cast<unsigned long long>(p.cfg.seed), p.cfg.drop, p.cfg.corrupt);
  if (p.cfg.delay_burst_s > 0)
    n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "; %s every frame %g ms late from %.2f s for %g s",
                       kFaultBusNames[p.delay_bus], p.cfg.delay_ms, p.delay_at_s, p.cfg.delay_burst_s);
  if (p.cfg.bus_off)
    std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "; %s driver bus-off at %.2f s",
                  kFaultBusNames[p.bus_off_bus], p.bus_off_at_s);
  return buf;
}

}  // namespace crease::world
