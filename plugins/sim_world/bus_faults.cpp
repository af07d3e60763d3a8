#include "plugins/sim_world/bus_faults.h"

#include <chrono>

namespace crease::world {

static_assert(kFaultBuses == drivers::sim::SimRobot::kDevices, "the plan names the simulated robot's buses");

BusFaultInjector::BusFaultInjector(drivers::sim::SimRobot& robot, const BusFaultPlan& plan)
    : robot_(robot), plan_(plan) {
  for (int b = 0; b < drivers::sim::SimRobot::kDevices; ++b) robot_.broker(b).set_faults(base_faults(b));
  thread_ = std::thread([this] { run(); });
}

BusFaultInjector::~BusFaultInjector() {
  {
    std::lock_guard lk(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

drivers::CanFaultConfig BusFaultInjector::base_faults(int bus) const {
  drivers::CanFaultConfig f;
  f.seed = plan_.cfg.seed * 31 + static_cast<std::uint64_t>(bus) + 1;  // one stream per bus
  f.drop = plan_.cfg.drop;
  f.corrupt = plan_.cfg.corrupt;
  f.delay_ns = static_cast<std::int64_t>(plan_.cfg.delay_ms * 1e6);
  return f;
}

void BusFaultInjector::apply_due(double t) {
  if (plan_.cfg.delay_burst_s > 0 && !delay_done_) {
    if (!delay_on_ && t >= plan_.delay_at_s) {
      drivers::CanFaultConfig f = base_faults(plan_.delay_bus);
      f.delay = 1.0;
      robot_.broker(plan_.delay_bus).set_faults(f);
      delay_on_ = true;
      started_.fetch_add(1);
    }
    if (delay_on_ && t >= plan_.delay_at_s + plan_.cfg.delay_burst_s) {
      robot_.broker(plan_.delay_bus).set_faults(base_faults(plan_.delay_bus));
      delay_on_ = false;
      delay_done_ = true;
      ended_.fetch_add(1);
    }
  }
  if (plan_.cfg.bus_off && !bus_off_done_ && t >= plan_.bus_off_at_s) {
    robot_.broker(plan_.bus_off_bus).force_bus_off(plan_.cfg.host_node);
    bus_off_done_ = true;
    bus_offs_.fetch_add(1);
  }
}

BusFaultCounts BusFaultInjector::counts() const noexcept {
  return {started_.load(), ended_.load(), bus_offs_.load()};
}

void BusFaultInjector::run() {
  std::unique_lock lk(mu_);
  while (!stop_) {
    lk.unlock();
    apply_due(world_s_.load(std::memory_order_relaxed));
    lk.lock();
    cv_.wait_for(lk, std::chrono::milliseconds(2), [this] { return stop_; });
  }
}

}  // namespace crease::world
