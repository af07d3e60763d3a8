#include "drivers/can/mock_reactor.h"

#include <pthread.h>
#include <sched.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <new>
#include <stdexcept>
#include <string>

namespace crease::drivers::mockwire {
namespace {

void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

[[noreturn]] void fail(const char* what) {
  throw std::runtime_error(std::string("mock CAN broker thread: ") + what + ": " + std::strerror(errno));
}

}  // namespace

std::shared_ptr<Reactor> Reactor::instance() {
  static std::mutex mu;
  static std::weak_ptr<Reactor> current;
  static pid_t owner = 0;
  std::lock_guard lk(mu);
  // After fork() the parent's reactor has no thread here: start a new one.
  std::shared_ptr<Reactor> r = owner == ::getpid() ? current.lock() : nullptr;
  if (!r) {
    r = std::shared_ptr<Reactor>(new Reactor);
    current = r;
    owner = ::getpid();
  }
  return r;
}

Reactor::Reactor() {
  epoll_fd_ = ::epoll_create1(EPOLL_CLOEXEC);
  if (epoll_fd_ < 0) fail("epoll_create1");
  doorbell_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  page_fd_ = ::memfd_create("crease-can-reactor", MFD_CLOEXEC);
  if (doorbell_fd_ < 0 || page_fd_ < 0 || ::fchmod(page_fd_, 0600) != 0 || ::ftruncate(page_fd_, 4096) != 0) {
    const int e = errno;
    for (int fd : {epoll_fd_, doorbell_fd_, page_fd_}) {
      if (fd >= 0) ::close(fd);
    }
    errno = e;
    fail("eventfd/memfd");
  }
  void* p = ::mmap(nullptr, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, page_fd_, 0);
  if (p == MAP_FAILED) {
    const int e = errno;
    for (int fd : {epoll_fd_, doorbell_fd_, page_fd_}) ::close(fd);
    errno = e;
    fail("mmap");
  }
  page_ = new (p) ReactorShm;
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = doorbell_fd_;
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, doorbell_fd_, &ev);
  thread_ = std::thread([this] { run(); });
}

Reactor::~Reactor() {
  stop_.store(true, std::memory_order_release);
  wake();
  thread_.join();
  ::munmap(page_, 4096);
  ::close(epoll_fd_);
  ::close(doorbell_fd_);
  ::close(page_fd_);
}

void Reactor::wake() noexcept {
  const std::uint64_t one = 1;
  (void)!::write(doorbell_fd_, &one, sizeof(one));
}

void Reactor::attach(BrokerCore* core, int listen_fd) {
  waiters_.fetch_add(1);
  std::lock_guard lk(mu_);
  waiters_.fetch_sub(1);
  waiters_.notify_all();
  cores_.push_back(core);
  watch_locked(core, listen_fd);
}

void Reactor::detach(BrokerCore* core) {
  waiters_.fetch_add(1);
  wake();
  std::lock_guard lk(mu_);
  waiters_.fetch_sub(1);
  waiters_.notify_all();
  cores_.erase(std::remove(cores_.begin(), cores_.end(), core), cores_.end());
  for (const auto& [fd, c] : fds_) {
    if (c == core) ::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
  }
  fds_.erase(std::remove_if(fds_.begin(), fds_.end(), [core](const auto& e) { return e.second == core; }), fds_.end());
}

void Reactor::watch_locked(BrokerCore* core, int fd) {
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = fd;
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &ev);
  fds_.emplace_back(fd, core);
}

void Reactor::unwatch_locked(int fd) {
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
  fds_.erase(std::remove_if(fds_.begin(), fds_.end(), [fd](const auto& e) { return e.first == fd; }), fds_.end());
}

bool Reactor::any_pending() const noexcept {
  for (const BrokerCore* c : cores_) {
    if (c->pending()) return true;
  }
  return false;
}

void Reactor::run() {
  epoll_event events[64];
  std::int64_t spin_until = 0;
  bool in_burst = false;
  (void)::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);  // the default 50 us slack would eat kLeadNs
  // The thread (simulated bus hardware) runs SCHED_FIFO 1 where permitted, so its wake-ups
  // come on time on a loaded machine. It did so only while it followed a periodic schedule; in
  // config/sim.yaml (the control loop's sends, the world's answers half a period later) it ran
  // SCHED_OTHER in 10 of 12 samples over a run, behind vision's OpenCV
  // workers and the machine's other work: every simulated device's answers stopped at once for
  // 50 ms and more while the world's loop was on time (config.sim_sequence, crease-trials).
  // Every poll is bounded (kSpinNs, kLeadNs + kWindowNs); a flood of frames would keep it
  // busy at FIFO 1 (the kernel's RT throttling still leaves other work 5 %).
  int inherited = SCHED_OTHER;
  sched_param inherited_param{};
  (void)pthread_getschedparam(pthread_self(), &inherited, &inherited_param);
  bool fifo = false;
  auto follow_schedule = [&](bool periodic) {
    if (inherited != SCHED_OTHER || periodic == fifo) return;
    sched_param sp{};
    sp.sched_priority = periodic ? 1 : 0;
    if (pthread_setschedparam(pthread_self(), periodic ? SCHED_FIFO : SCHED_OTHER, &sp) == 0) fifo = periodic;
  };
  std::unique_lock lk(mu_);
  while (!stop_.load(std::memory_order_acquire)) {
    if (waiters_.load(std::memory_order_acquire) > 0) {  // hand the lock to attach()/detach()
      // Blocked, not spinning: at SCHED_FIFO a yield gives the CPU to no SCHED_OTHER waiter,
      // so on a CPU the loops keep busy the waiter might never get the lock.
      lk.unlock();
      for (int w = waiters_.load(std::memory_order_acquire); w > 0; w = waiters_.load(std::memory_order_acquire))
        waiters_.wait(w, std::memory_order_acquire);
      lk.lock();
      continue;
    }
    const std::int64_t now = rt::now_ns();
    std::int64_t first_sent = -1;  // earliest send time of what moved (not when we noticed)
    for (BrokerCore* c : cores_) {
      const std::int64_t t = c->tick(now);
      if (t >= 0) first_sent = first_sent < 0 ? t : std::min(first_sent, t);
    }
    if (first_sent >= 0) {
      // A burst starts after a sleep (the devices' answers to a cycle's frames, within
      // kMinPeriodNs, belong to that cycle's burst).
      if (!in_burst && bursts_.on_activity(first_sent)) in_burst = true;
      spin_until = rt::now_ns() + kSpinNs;
    }
    if (any_pending()) continue;
    // Poll the rings a little longer: the answers to what just moved are usually close, and
    // so is a predicted burst.
    const std::int64_t predicted = in_burst ? -1 : bursts_.next_ns();
    const std::int64_t t_spin = rt::now_ns();
    if (predicted > 0 && t_spin >= predicted - kLeadNs && t_spin < predicted + kWindowNs) {
      spin_until = std::max(spin_until, predicted + kWindowNs);
    }
    bool again = false;
    while (rt::now_ns() < spin_until && waiters_.load(std::memory_order_relaxed) == 0 &&
           !stop_.load(std::memory_order_relaxed)) {
      if (any_pending()) {
        again = true;
        break;
      }
      cpu_relax();
    }
    if (again) continue;
    in_burst = false;
    // Sleep. A node that pushes after this store sees `sleeping` and writes the doorbell;
    // one that pushed before it is seen by the check below (seq_cst on both sides).
    page_->sleeping.store(1, std::memory_order_seq_cst);
    if (any_pending()) {
      page_->sleeping.store(0, std::memory_order_relaxed);
      continue;
    }
    std::int64_t next = -1;
    for (const BrokerCore* c : cores_) {
      const std::int64_t d = c->next_deadline_ns();
      if (d >= 0) next = next < 0 ? d : std::min(next, d);
    }
    const std::int64_t before = rt::now_ns();
    const std::int64_t next_burst = bursts_.next_ns();
    follow_schedule(true);  // see above: FIFO 1 whenever permitted
    if (next_burst > 0 && next_burst - kLeadNs > before) {
      next = next < 0 ? next_burst - kLeadNs : std::min(next, next_burst - kLeadNs);
    }
    timespec timeout{};
    if (next >= 0) {
      const std::int64_t wait = std::max<std::int64_t>(0, next - before);
      timeout.tv_sec = wait / 1'000'000'000;
      timeout.tv_nsec = wait % 1'000'000'000;
    }
    lk.unlock();
    const int n = ::epoll_pwait2(epoll_fd_, events, 64, next >= 0 ? &timeout : nullptr, nullptr);
    lk.lock();
    page_->sleeping.store(0, std::memory_order_relaxed);
    const std::int64_t t = rt::now_ns();
    for (int i = 0; i < n; ++i) {
      const int fd = events[i].data.fd;
      if (fd == doorbell_fd_) {
        std::uint64_t v;
        (void)!::read(doorbell_fd_, &v, sizeof(v));
        continue;
      }
      const auto it = std::find_if(fds_.begin(), fds_.end(), [fd](const auto& e) { return e.first == fd; });
      if (it != fds_.end()) it->second->on_fd(fd, events[i].events, t);
    }
  }
}

}  // namespace crease::drivers::mockwire
