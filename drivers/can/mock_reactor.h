// The one thread that serves every MockCanBroker of a process (internal to the mock bus).
// Brokers attach to it; it drains their nodes' rings, runs their timers and dispatches their
// sockets' events. After it moved frames it keeps polling the rings for kSpinNs before it
// sleeps, so the frames a control cycle sends to several buses, and the devices' answers,
// cost one wake-up of this thread, not one per bus and per frame. When bursts of traffic
// come at a steady period (a control loop), it wakes itself kLeadNs before the next one is
// due and polls until kWindowNs after it, so the loop's sends find it awake and pay no
// system call at all; a burst that misses the window wakes it through the eventfd as usual.
// It runs SCHED_FIFO 1 where the process may (like the simulated devices), so it wakes on time
// on a loaded machine (mock_reactor.cpp: why not only while it follows a schedule).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "drivers/can/mock_wire.h"
#include "rt/clock.h"

namespace crease::drivers::mockwire {

// Predicts when the next burst of traffic starts, when bursts come on a steady schedule (a
// control loop's period). Phase-locked: a start within 5 % of the period of the expected
// time confirms the schedule and corrects its phase and period (an alpha-beta filter); one
// start off the schedule (a loop that woke late) keeps it; two in a row re-learn the period.
// Pure logic.
class BurstPredictor {
 public:
  static constexpr std::int64_t kMinPeriodNs = 200'000;    // closer starts belong to one burst
  static constexpr std::int64_t kMaxPeriodNs = 20'000'000;
  static constexpr std::int64_t kToleranceDiv = 20;        // on schedule: within period / 20
  static constexpr int kConfirmations = 2;                 // starts on schedule before predicting

  // Activity at now_ns; counts as a burst start unless one was recorded within kMinPeriodNs.
  // Returns true if it did.
  bool on_activity(std::int64_t now_ns) noexcept {
    if (last_ != 0 && now_ns - last_ < kMinPeriodNs) return false;
    if (period_ != 0) {
      const std::int64_t err = now_ns - expected_;
      if (err <= period_ / kToleranceDiv && -err <= period_ / kToleranceDiv) {
        confirmed_ = confirmed_ < kConfirmations ? confirmed_ + 1 : kConfirmations;
        missed_ = false;
        // Alpha-beta tracking: the schedule's phase and period follow the starts.
        period_ += err / 16;
        expected_ += period_ + err / 4;
        last_ = now_ns;
        return true;
      }
      if (!missed_ && confirmed_ > 0 && err < 4 * period_) {  // one outlier: keep the schedule
        missed_ = true;
        while (expected_ <= now_ns) expected_ += period_;
        last_ = now_ns;
        return true;
      }
    }
    // (Re)learn the period from the last interval.
    period_ = last_ != 0 ? now_ns - last_ : 0;
    if (period_ < kMinPeriodNs || period_ > kMaxPeriodNs) period_ = 0;
    expected_ = now_ns + period_;
    confirmed_ = 0;
    missed_ = false;
    last_ = now_ns;
    return true;
  }
  // Expected start of the next burst, or -1 while no schedule is confirmed.
  [[nodiscard]] std::int64_t next_ns() const noexcept {
    return period_ != 0 && confirmed_ >= kConfirmations ? expected_ : -1;
  }

 private:
  std::int64_t last_ = 0;      // last start; 0 = none
  std::int64_t period_ = 0;    // 0 = none
  std::int64_t expected_ = 0;  // next start on the schedule
  int confirmed_ = 0;
  bool missed_ = false;        // the last start was off the schedule
};

// What the reactor drives; MockCanBroker implements it. All calls come from the reactor
// thread with the reactor's lock held.
class BrokerCore {
 public:
  virtual ~BrokerCore() = default;
  virtual void on_fd(int fd, std::uint32_t epoll_events, std::int64_t now) = 0;
  // Drains rings, runs due timers, flushes outboxes. Returns -1 if no record moved, else
  // the earliest time a node stamped on a record it drained (when the node sent it), or now.
  virtual std::int64_t tick(std::int64_t now) = 0;
  // True if tick() has records to move now (cheap: ring indices only).
  [[nodiscard]] virtual bool pending() const noexcept = 0;
  // Next CLOCK_MONOTONIC time tick() must run without an event, or -1.
  [[nodiscard]] virtual std::int64_t next_deadline_ns() const = 0;
};

class Reactor {
 public:
  static constexpr std::int64_t kSpinNs = 15'000;
  static constexpr std::int64_t kLeadNs = 60'000;
  static constexpr std::int64_t kWindowNs = 150'000;

  // The process's reactor, started on first use; it stops when the last owner lets go.
  static std::shared_ptr<Reactor> instance();
  ~Reactor();
  Reactor(const Reactor&) = delete;
  Reactor& operator=(const Reactor&) = delete;

  // From any thread (not the reactor's). attach() watches the core's first fd; detach()
  // returns once the reactor no longer touches the core or any fd it watched.
  void attach(BrokerCore* core, int listen_fd);
  void detach(BrokerCore* core);
  // From the reactor thread (in a BrokerCore call).
  void watch_locked(BrokerCore* core, int fd);
  void unwatch_locked(int fd);
  // From any thread: makes the reactor run a tick soon.
  void wake() noexcept;

  [[nodiscard]] int doorbell_fd() const noexcept { return doorbell_fd_; }
  [[nodiscard]] int page_fd() const noexcept { return page_fd_; }

 private:
  Reactor();
  void run();
  [[nodiscard]] bool any_pending() const noexcept;
  BurstPredictor bursts_;
  int epoll_fd_ = -1;
  int doorbell_fd_ = -1;  // eventfd: nodes write it when they find `sleeping` set
  int page_fd_ = -1;      // memfd holding the ReactorShm, handed to nodes
  ReactorShm* page_ = nullptr;
  std::mutex mu_;
  std::atomic<int> waiters_{0};  // threads waiting for mu_ (the spin yields to them)
  std::atomic<bool> stop_{false};
  std::vector<BrokerCore*> cores_;
  std::vector<std::pair<int, BrokerCore*>> fds_;
  std::thread thread_;
};

}  // namespace crease::drivers::mockwire
