// Runs a simulated device's step() on its own thread: wakes when its fd is readable or every
// period_ms, whichever comes first. Not RT code (a test and simulation helper), but it can run
// under SCHED_FIFO (fifo_priority > 0; silently stays SCHED_OTHER where that is not permitted)
// so benchmarks measure the bus and not the scheduler.
#pragma once

#include <poll.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <functional>
#include <thread>

#include "rt/clock.h"

namespace crease::drivers::sim {

class DeviceThread {
 public:
  DeviceThread(int fd, std::function<void(std::int64_t)> step, int period_ms = 1, int fifo_priority = 0)
      : thread_([this, fd, step = std::move(step), period_ms, fifo_priority] {
          if (fifo_priority > 0) {
            sched_param sp{};
            sp.sched_priority = fifo_priority;
            (void)pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
          }
          while (!stop_.load(std::memory_order_acquire)) {
            pollfd p{fd, POLLIN, 0};
            (void)::poll(&p, 1, period_ms);
            step(rt::now_ns());
          }
        }) {}
  ~DeviceThread() {
    stop_.store(true, std::memory_order_release);
    thread_.join();
  }
  DeviceThread(const DeviceThread&) = delete;
  DeviceThread& operator=(const DeviceThread&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace crease::drivers::sim
