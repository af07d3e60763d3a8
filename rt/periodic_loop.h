// A periodic thread: wakes at absolute deadlines (clock_nanosleep TIMER_ABSTIME), runs its body,
// records its timing, never waits on anything else.
//
// Overrun policy (the only one): when the body ends after the next deadline, the deadlines that
// already passed are skipped and counted in missed_periods, never replayed as a burst; the loop
// resumes at the first deadline still in the future. Cycle numbers count deadlines, so skipped
// periods leave gaps in them.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "rt/histogram.h"
#include "rt/rt_setup.h"

namespace crease::rt {

// What the body learns about the cycle it runs in.
struct CycleClock {
  std::uint64_t cycle = 0;        // deadline index since start (0, 1, 2, ...; gaps after skips)
  std::int64_t deadline_ns = 0;   // scheduled wake-up, CLOCK_MONOTONIC
  std::int64_t wake_ns = 0;       // actual wake-up
  std::int64_t period_ns = 0;
};

// Written by the loop thread only; read by anyone.
struct LoopTiming {
  Histogram wakeup_latency;  // wake_ns - deadline_ns
  Histogram execution;       // time spent in the body
  Histogram period;          // wake_ns - previous wake_ns
  std::atomic<std::uint64_t> cycles{0};          // bodies run
  std::atomic<std::uint64_t> overruns{0};        // bodies that ended after the next deadline
  std::atomic<std::uint64_t> missed_periods{0};  // deadlines skipped by the overrun policy
  // Overruns whose wake-up itself came at or after the next deadline: the machine (or a
  // higher-priority thread) held the loop, not its body.
  std::atomic<std::uint64_t> late_wakes{0};
  std::atomic<std::int64_t> started_ns{0};       // first deadline
};

class PeriodicLoop {
 public:
  // Runs once per cycle on the loop thread. Must be RT-safe and must not throw.
  using Body = void (*)(void* ctx, const CycleClock& clock) noexcept;

  struct Settings {
    std::string name;
    std::int64_t period_ns = 1'000'000;
    ThreadSettings thread;
    // Deadlines lie on the period's grid of CLOCK_MONOTONIC shifted by this, in [0, period):
    // t = k period + phase_ns. Loops of one rate keep a fixed phase to each other (a loop that
    // answers another's frames runs phase_ns after it, as a shifted EtherCAT SYNC0 would).
    std::int64_t phase_ns = 0;
  };

  PeriodicLoop(Settings settings, Body body, void* ctx);
  ~PeriodicLoop();  // stops the thread if running
  PeriodicLoop(const PeriodicLoop&) = delete;
  PeriodicLoop& operator=(const PeriodicLoop&) = delete;

  // Starts the thread and waits until it has applied its settings; returns what was applied
  // and what was refused (and why). Non-RT. Calling start twice is a bug.
  std::vector<SetupStep> start();
  // Asks the thread to finish its current cycle, then joins it. Non-RT. Idempotent.
  void stop();

  [[nodiscard]] bool running() const noexcept { return running_.load(std::memory_order_acquire); }
  [[nodiscard]] const Settings& settings() const noexcept { return settings_; }
  [[nodiscard]] const LoopTiming& timing() const noexcept { return timing_; }
  [[nodiscard]] LoopTiming& timing() noexcept { return timing_; }
  // Whether SCHED_FIFO was in force on the thread (valid after start()).
  [[nodiscard]] bool fifo_applied() const noexcept { return fifo_.load(std::memory_order_relaxed); }

 private:
  void run_thread();

  Settings settings_;
  Body body_;
  void* ctx_;
  LoopTiming timing_;
  std::thread thread_;
  std::vector<SetupStep> steps_;
  std::atomic<bool> setup_done_{false};
  std::atomic<bool> stop_{false};
  std::atomic<bool> running_{false};
  std::atomic<bool> fifo_{false};
};

}  // namespace crease::rt
