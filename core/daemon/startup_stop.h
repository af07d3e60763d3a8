// A stop asked for while creased starts. SIGINT and SIGTERM are blocked in every thread from
// main's first line (the main loop takes them with sigtimedwait). During start-up a
// StartupWatch's thread takes them instead:
//   - check_startup_stop(), called between the stages of start-up (configuration, each
//     plugin's load and configure, memory lock and prefault, the control socket, the loops'
//     start), sees the stop and throws StartupStopped; creased then unwinds what it built
//     (plugins deactivated and unloaded), says so and exits 0 without running a loop;
//   - a stage that has not returned, or an unwinding that has not ended, `grace` after the
//     signal (default 0.5 s: one plugin's configure that takes a minute, a hung device) is
//     cut short: the watch prints "stopped by SIGTERM during start-up, in STAGE, ... exiting
//     without unwinding; no loop ran" and ends the process (exit 0; the kernel reclaims its
//     memory, descriptors and threads; no loop ran, so no command was ever sent).
// So a stop is honoured within the grace (plus the watch's wake-up) at any point of start-up.
// Grace 0 waits for the stage however long (the stop is then taken at the next boundary).
//
//   StartupWatch watch;                               // first thing in main, signals blocked
//   ... load the configuration; watch.set_grace(cfg.daemon.startup_stop_grace_s);
//   check_startup_stop("before plugin 2 of 3 ('x')", "plugin 2 of 3 ('x'): load and configure");
//   ... finish_startup("before starting the loops");  // the watch's thread ends; signals from
//                                                       // here on are the main loop's
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace crease::daemon {

class StartupStopped : public std::runtime_error {
 public:
  StartupStopped(int signal, const std::string& stage);
  [[nodiscard]] int signal() const noexcept { return signal_; }

 private:
  int signal_;
};

class StartupWatch {
 public:
  static constexpr double kDefaultGraceS = 0.5;
  // Starts the watching thread; SIGINT and SIGTERM must be blocked in every thread already.
  // Throws std::system_error when the thread or its descriptors cannot be made. At most one
  // watch at a time (check_startup_stop consults it).
  explicit StartupWatch(double grace_s = kDefaultGraceS);
  ~StartupWatch();  // ends the thread (finish()); a signal it has not taken stays pending
  StartupWatch(const StartupWatch&) = delete;
  StartupWatch& operator=(const StartupWatch&) = delete;

  // Seconds a stage may go on after a stop before the process is ended; 0 = no limit.
  void set_grace(double grace_s) noexcept;
  // The stop taken so far: SIGINT, SIGTERM or 0.
  [[nodiscard]] int taken() const noexcept { return signal_.load(std::memory_order_acquire); }
  // Names the stage under way (for the message of a cut-short stage).
  void enter(const std::string& stage);
  // Ends the thread. Returns the stop it took (0 when none); a later signal stays pending.
  int finish();

 private:
  void run();
  [[noreturn]] void cut_short(int sig);

  std::atomic<int> signal_{0};
  std::atomic<std::int64_t> grace_ns_;
  std::atomic<bool> finishing_{false};
  int signal_fd_ = -1, wake_fd_ = -1;
  std::mutex stage_mutex_;
  std::string stage_ = "start-up";
  std::thread thread_;
};

// Throws StartupStopped ("stopped by SIGTERM during start-up, BOUNDARY") when a stop was asked
// for: taken by the current StartupWatch, or (with none, e.g. a Daemon built by a test) pending
// for the process, then taken. Else names UNDER_WAY as the watch's current stage. Never blocks.
void check_startup_stop(const std::string& boundary, const std::string& under_way = "start-up");

// The end of start-up: check_startup_stop(BOUNDARY), then the current watch's thread ends (a
// stop it took meanwhile throws as well). Signals from here on stay pending for the main loop.
void finish_startup(const std::string& boundary);

}  // namespace crease::daemon
