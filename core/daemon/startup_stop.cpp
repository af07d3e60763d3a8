#include "core/daemon/startup_stop.h"

#include <poll.h>
#include <signal.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <system_error>

#include "rt/clock.h"

namespace crease::daemon {
namespace {

std::atomic<StartupWatch*> g_watch{nullptr};

const char* name_of(int sig) { return sig == SIGINT ? "SIGINT" : "SIGTERM"; }

sigset_t stop_signals() {
  sigset_t s;
  sigemptyset(&s);
  sigaddset(&s, SIGINT);
  sigaddset(&s, SIGTERM);
  return s;
}

// A stop pending for the process (no watch to take it), taken; 0 when none.
int take_pending() {
  sigset_t pending;
  sigemptyset(&pending);
  if (sigpending(&pending) != 0) return 0;
  if (sigismember(&pending, SIGINT) != 1 && sigismember(&pending, SIGTERM) != 1) return 0;
  const sigset_t stop = stop_signals();
  const timespec now{0, 0};
  const int sig = sigtimedwait(&stop, nullptr, &now);
  return sig == SIGINT ? SIGINT : SIGTERM;
}

std::int64_t grace_to_ns(double grace_s) {
  if (!(grace_s > 0)) return 0;
  return static_cast<std::int64_t>(std::llround(std::fmin(grace_s, 1e6) * 1e9));
}

void write_all(int fd, const std::string& s) {
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = ::write(fd, s.data() + done, s.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

StartupStopped::StartupStopped(int signal, const std::string& stage)
    : std::runtime_error(std::string("stopped by ") + name_of(signal) + " during start-up, " + stage),
      signal_(signal) {}

StartupWatch::StartupWatch(double grace_s) : grace_ns_(grace_to_ns(grace_s)) {
  StartupWatch* none = nullptr;
  if (!g_watch.compare_exchange_strong(none, this)) throw std::logic_error("one StartupWatch at a time");
  const sigset_t stop = stop_signals();
  signal_fd_ = ::signalfd(-1, &stop, SFD_CLOEXEC | SFD_NONBLOCK);
  wake_fd_ = signal_fd_ < 0 ? -1 : ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (signal_fd_ < 0 || wake_fd_ < 0) {
    const int err = errno;
    if (signal_fd_ >= 0) ::close(signal_fd_);
    g_watch.store(nullptr);
    throw std::system_error(err, std::generic_category(), "signalfd/eventfd for the start-up watch");
  }
  try {
    thread_ = std::thread([this] { run(); });
  } catch (...) {
    ::close(signal_fd_);
    ::close(wake_fd_);
    g_watch.store(nullptr);
    throw;
  }
}

StartupWatch::~StartupWatch() {
  finish();
  ::close(signal_fd_);
  ::close(wake_fd_);
  g_watch.store(nullptr);
}

void StartupWatch::set_grace(double grace_s) noexcept {
  grace_ns_.store(grace_to_ns(grace_s));
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);  // the thread recomputes its deadline
}

void StartupWatch::enter(const std::string& stage) {
  const std::lock_guard<std::mutex> lock(stage_mutex_);
  stage_ = stage;
}

int StartupWatch::finish() {
  if (thread_.joinable()) {
    finishing_.store(true);
    const std::uint64_t one = 1;
    (void)!::write(wake_fd_, &one, sizeof one);
    thread_.join();
  }
  return taken();
}

void StartupWatch::run() {
  pollfd fds[2] = {{signal_fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
  std::int64_t taken_ns = 0;
  while (!finishing_.load()) {
    int timeout_ms = -1;
    if (taken() != 0) {
      const std::int64_t grace = grace_ns_.load();
      if (grace > 0) {
        const std::int64_t left = taken_ns + grace - rt::now_ns();
        if (left <= 0) cut_short(taken());
        timeout_ms = static_cast<int>(std::min<std::int64_t>((left + 999'999) / 1'000'000, 60'000));
      }
    }
    const int r = ::poll(fds, 2, timeout_ms);
    if (r < 0 && errno != EINTR) return;  // cannot watch: the stage boundaries still take the stop
    if (fds[1].revents & POLLIN) {
      std::uint64_t n = 0;
      (void)!::read(wake_fd_, &n, sizeof n);
    }
    if (fds[0].fd >= 0 && (fds[0].revents & POLLIN)) {
      signalfd_siginfo si{};
      if (::read(signal_fd_, &si, sizeof si) == static_cast<ssize_t>(sizeof si)) {
        taken_ns = rt::now_ns();
        signal_.store(static_cast<int>(si.ssi_signo), std::memory_order_release);
        fds[0].fd = -1;  // the first stop is the one acted upon; later ones stay pending
      }
    }
  }
}

void StartupWatch::cut_short(int sig) {
  std::string stage;
  {
    const std::lock_guard<std::mutex> lock(stage_mutex_);
    stage = stage_;
  }
  char grace[32];
  std::snprintf(grace, sizeof grace, "%.2g", static_cast<double>(grace_ns_.load()) * 1e-9);
  // What the main thread has written so far first (unless it holds stdout: then without it).
  if (ftrylockfile(stdout) == 0) {
    std::fflush(stdout);
    funlockfile(stdout);
  }
  write_all(STDOUT_FILENO, std::string("creased: stopped by ") + name_of(sig) + " during start-up, in " + stage +
                               ", still under way " + grace + " s after the signal: exiting without unwinding it;" +
                               " no loop ran\n");
  ::_exit(0);
}

void check_startup_stop(const std::string& boundary, const std::string& under_way) {
  StartupWatch* w = g_watch.load();
  const int sig = w != nullptr ? w->taken() : take_pending();
  if (sig != 0) {
    if (w != nullptr) w->enter("unwinding what start-up built (stopped " + boundary + ")");
    throw StartupStopped(sig, boundary);
  }
  if (w != nullptr) w->enter(under_way);
}

void finish_startup(const std::string& boundary) {
  check_startup_stop(boundary, "starting the loops");
  StartupWatch* w = g_watch.load();
  if (w == nullptr) return;
  if (const int sig = w->finish(); sig != 0) throw StartupStopped(sig, boundary);
}

}  // namespace crease::daemon
