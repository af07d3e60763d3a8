// BusFaultInjector: applies a drawn plan of bus faults (bus_fault_plan.h) to the simulated
// robot's buses (their brokers) as the world's time reaches each fault.
//
// The brokers' fault controls take a lock (drivers/can/mock_can_broker.h), so the world's RT
// step only publishes its time (tick_rt, one atomic store) and a thread of the injector's own
// applies what has come due, polling every few milliseconds of wall time.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "drivers/simdevice/sim_robot.h"
#include "plugins/sim_world/bus_fault_plan.h"

namespace crease::world {

// What the injector has done so far (any thread).
struct BusFaultCounts {
  int delay_bursts_started = 0;
  int delay_bursts_ended = 0;
  int bus_offs = 0;
};

class BusFaultInjector {
 public:
  // Sets every broker's per-frame faults and starts the thread. ROBOT must outlive this.
  BusFaultInjector(drivers::sim::SimRobot& robot, const BusFaultPlan& plan);
  ~BusFaultInjector();  // stops the thread; the brokers keep their last faults
  BusFaultInjector(const BusFaultInjector&) = delete;
  BusFaultInjector& operator=(const BusFaultInjector&) = delete;

  // The world's time now (s). RT: one atomic store.
  void tick_rt(double world_s) noexcept { world_s_.store(world_s, std::memory_order_relaxed); }

  [[nodiscard]] BusFaultCounts counts() const noexcept;
  [[nodiscard]] const BusFaultPlan& plan() const noexcept { return plan_; }

 private:
  void apply_due(double t);  // whatever has come due at world time T (the thread's step)
  [[nodiscard]] drivers::CanFaultConfig base_faults(int bus) const;
  void run();

  drivers::sim::SimRobot& robot_;
  BusFaultPlan plan_;
  std::atomic<double> world_s_{0.0};
  std::atomic<int> started_{0}, ended_{0}, bus_offs_{0};
  bool delay_on_ = false, delay_done_ = false, bus_off_done_ = false;  // the thread's
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace crease::world
