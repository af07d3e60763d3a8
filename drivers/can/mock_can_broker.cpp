#include "drivers/can/mock_can_broker.h"

#include <fcntl.h>
#include <linux/can/error.h>
#include <signal.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <map>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

#include "drivers/can/mock_wire.h"

namespace crease::drivers {
namespace {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

[[noreturn]] void fail(const std::string& bus, const char* what) {
  throw std::runtime_error("mock CAN bus '" + bus + "': " + what + ": " + std::strerror(errno));
}

}  // namespace

namespace mockwire {
socklen_t make_address(const std::string& bus_name, sockaddr_un& out) {
  const std::string path = std::string("crease-can/") + bus_name;
  if (bus_name.empty() || path.size() + 1 > sizeof(out.sun_path)) {
    throw std::invalid_argument("mock CAN bus name '" + bus_name + "' is empty or too long");
  }
  std::memset(&out, 0, sizeof(out));
  out.sun_family = AF_UNIX;
  std::memcpy(out.sun_path + 1, path.data(), path.size());  // abstract namespace: leading NUL
  return static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + path.size());
}
}  // namespace mockwire

struct MockCanBroker::Impl {
  int listen_fd = -1;
  int epoll_fd = -1;
  int wake_fd = -1;
  std::atomic<bool> stop{false};

  struct Client {
    int fd;
    std::uint32_t node = 0xFFFFFFFFu;
    bool bus_off = false;
    std::deque<mockwire::Record> outbox;  // records its socket did not take yet
    std::int64_t progress_ns = 0;         // last time its outbox started or moved
    std::uint32_t events = EPOLLIN;       // current epoll interest
  };
  // A node whose socket is full gets an outbox; while an outbox is non-empty and draining
  // (it moved within kStallNs) the broker stops reading from nodes: back-pressure reaches the
  // senders as no_buffers instead of frames being lost. A node that stops reading for longer
  // no longer holds the bus up: its outbox fills to the cap and then it loses its own frames
  // (counted as rx_overflow), like a CAN socket's receive queue.
  static constexpr std::size_t kOutboxCap = 4096;
  static constexpr std::int64_t kStallNs = 100'000'000;  // a reader paused by the scheduler is not idle
  bool reading = true;
  std::vector<Client> clients;

  struct Delayed {
    std::int64_t due_ns;
    std::uint64_t order;
    int from_fd;
    mockwire::Record rec;
  };
  std::vector<Delayed> delayed;  // kept sorted by (due_ns, order)
  std::uint64_t order = 0;
  std::optional<std::pair<int, mockwire::Record>> held;  // reorder fault
  std::int64_t held_since = 0;
  std::int64_t bus_free_at = 0;

  mutable std::mutex mu;  // guards everything below
  CanFaultConfig faults;
  std::mt19937_64 rng{1};
  std::vector<std::uint32_t> silent;
  std::vector<std::uint32_t> bus_off_requests;
  std::vector<CanFrame> error_injections;
  MockCanBrokerStats stats;
};

MockCanBroker::MockCanBroker(MockCanBrokerConfig cfg) : cfg_(std::move(cfg)), impl_(new Impl) {
  sockaddr_un addr{};
  const socklen_t len = mockwire::make_address(cfg_.name, addr);
  impl_->listen_fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (impl_->listen_fd < 0) fail(cfg_.name, "socket");
  if (::bind(impl_->listen_fd, reinterpret_cast<sockaddr*>(&addr), len) != 0) {
    const int e = errno;
    ::close(impl_->listen_fd);
    delete impl_;
    errno = e;
    fail(cfg_.name, "bind (is another broker serving this bus?)");
  }
  ::listen(impl_->listen_fd, 64);
  impl_->epoll_fd = ::epoll_create1(EPOLL_CLOEXEC);
  impl_->wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = impl_->listen_fd;
  ::epoll_ctl(impl_->epoll_fd, EPOLL_CTL_ADD, impl_->listen_fd, &ev);
  ev.data.fd = impl_->wake_fd;
  ::epoll_ctl(impl_->epoll_fd, EPOLL_CTL_ADD, impl_->wake_fd, &ev);
  thread_ = std::thread([this] { run(); });
}

MockCanBroker::~MockCanBroker() {
  impl_->stop.store(true, std::memory_order_release);
  const std::uint64_t one = 1;
  (void)!::write(impl_->wake_fd, &one, sizeof(one));
  thread_.join();
  for (auto& c : impl_->clients) ::close(c.fd);
  ::close(impl_->listen_fd);
  ::close(impl_->epoll_fd);
  ::close(impl_->wake_fd);
  delete impl_;
}

void MockCanBroker::set_faults(const CanFaultConfig& f) {
  std::lock_guard lk(impl_->mu);
  impl_->faults = f;
  impl_->rng.seed(f.seed);
}

void MockCanBroker::set_silent(std::uint32_t node_id, bool s) {
  std::lock_guard lk(impl_->mu);
  auto& v = impl_->silent;
  v.erase(std::remove(v.begin(), v.end(), node_id), v.end());
  if (s) v.push_back(node_id);
}

void MockCanBroker::force_bus_off(std::uint32_t node_id) {
  {
    std::lock_guard lk(impl_->mu);
    impl_->bus_off_requests.push_back(node_id);
  }
  const std::uint64_t one = 1;
  (void)!::write(impl_->wake_fd, &one, sizeof(one));
}

void MockCanBroker::inject_error_frame(const CanFrame& err) {
  {
    std::lock_guard lk(impl_->mu);
    impl_->error_injections.push_back(err);
  }
  const std::uint64_t one = 1;
  (void)!::write(impl_->wake_fd, &one, sizeof(one));
}

MockCanBrokerStats MockCanBroker::stats() const {
  std::lock_guard lk(impl_->mu);
  return impl_->stats;
}

int MockCanBroker::connected_nodes() const { return stats().nodes; }

void MockCanBroker::run() {
  Impl& m = *impl_;
  auto set_events = [&](Impl::Client& c, std::uint32_t ev) {
    if (c.events == ev) return;
    c.events = ev;
    epoll_event e{};
    e.events = ev;
    e.data.fd = c.fd;
    ::epoll_ctl(m.epoll_fd, EPOLL_CTL_MOD, c.fd, &e);
  };
  auto send_to = [&](Impl::Client& c, const mockwire::Record& r) {
    if (c.outbox.empty()) {
      if (::send(c.fd, &r, sizeof(r), MSG_DONTWAIT | MSG_NOSIGNAL) == sizeof(r)) {
        ++m.stats.forwarded;
        return;
      }
      if (errno != EAGAIN && errno != EWOULDBLOCK) {
        ++m.stats.rx_overflow;  // node gone; its hang-up is handled by the read side
        return;
      }
    }
    if (c.outbox.size() >= Impl::kOutboxCap) {
      ++m.stats.rx_overflow;
      return;
    }
    if (c.outbox.empty()) c.progress_ns = now_ns();
    c.outbox.push_back(r);
  };
  auto flush = [&](Impl::Client& c) {
    while (!c.outbox.empty()) {
      if (::send(c.fd, &c.outbox.front(), sizeof(mockwire::Record), MSG_DONTWAIT | MSG_NOSIGNAL) !=
          sizeof(mockwire::Record)) {
        if (errno != EAGAIN && errno != EWOULDBLOCK) c.outbox.clear();
        return;
      }
      ++m.stats.forwarded;
      c.outbox.pop_front();
      c.progress_ns = now_ns();
    }
  };
  auto broadcast = [&](int from_fd, const mockwire::Record& r) {
    for (auto& c : m.clients) {
      if (c.fd != from_fd && c.node != 0xFFFFFFFFu) send_to(c, r);
    }
  };
  // Bus-time model: the frame occupies the virtual bus after the previous one finished.
  auto bus_time = [&](mockwire::Record& r, std::int64_t now) {
    if (cfg_.nominal_bps == 0) {
      r.timestamp_ns = now;
      return;
    }
    const std::int64_t dt = can_frame_time_ns(r.frame, cfg_.nominal_bps, cfg_.data_bps);
    const std::int64_t start = std::max(now, m.bus_free_at);
    m.bus_free_at = start + dt;
    m.stats.busy_ns += dt;
    r.timestamp_ns = m.bus_free_at;
  };
  auto schedule = [&](int from_fd, const mockwire::Record& r, std::int64_t due) {
    Impl::Delayed d{due, m.order++, from_fd, r};
    auto it = std::upper_bound(m.delayed.begin(), m.delayed.end(), d, [](const auto& a, const auto& b) {
      return a.due_ns < b.due_ns || (a.due_ns == b.due_ns && a.order < b.order);
    });
    m.delayed.insert(it, d);
  };
  // One frame from a node: apply faults (under mu), then forward.
  auto on_frame = [&](Impl::Client& from, mockwire::Record r, std::int64_t now) {
    ++m.stats.received;
    r.node = from.node;
    const auto& f = m.faults;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (from.bus_off || std::find(m.silent.begin(), m.silent.end(), from.node) != m.silent.end()) {
      ++m.stats.dropped_fault;
      return;
    }
    if (f.error_frame > 0 && u(m.rng) < f.error_frame) {
      mockwire::Record e;
      e.frame.can_id = CAN_ERR_FLAG | CAN_ERR_PROT | CAN_ERR_BUSERROR;
      e.frame.len = CAN_ERR_DLC;
      e.timestamp_ns = now;
      broadcast(-1, e);
    }
    if (f.drop > 0 && u(m.rng) < f.drop) {
      ++m.stats.dropped_fault;
      return;
    }
    if (f.corrupt > 0 && u(m.rng) < f.corrupt && r.frame.len > 0) {
      const std::uint32_t bit = static_cast<std::uint32_t>(m.rng() % (8u * r.frame.len));
      r.frame.data[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    }
    bus_time(r, now);
    const int copies = (f.duplicate > 0 && u(m.rng) < f.duplicate) ? 2 : 1;
    if (f.delay > 0 && u(m.rng) < f.delay) {
      for (int i = 0; i < copies; ++i) schedule(from.fd, r, now + f.delay_ns);
      return;
    }
    if (f.reorder > 0 && !m.held && u(m.rng) < f.reorder) {
      m.held.emplace(from.fd, r);
      m.held_since = now;
      return;
    }
    for (int i = 0; i < copies; ++i) {
      if (cfg_.pace && r.timestamp_ns > now) {
        schedule(from.fd, r, r.timestamp_ns);
      } else {
        broadcast(from.fd, r);
      }
    }
    if (m.held) {
      broadcast(m.held->first, m.held->second);
      m.held.reset();
    }
  };

  std::vector<epoll_event> events(64);
  while (!m.stop.load(std::memory_order_acquire)) {
    int timeout_ms = -1;
    {
      std::lock_guard lk(m.mu);
      std::int64_t next = -1;
      if (!m.delayed.empty()) next = m.delayed.front().due_ns;
      if (m.held) next = next < 0 ? m.held_since + 1'000'000 : std::min(next, m.held_since + 1'000'000);
      if (!m.reading) {  // re-check stalled outboxes
        const std::int64_t recheck = now_ns() + Impl::kStallNs;
        next = next < 0 ? recheck : std::min(next, recheck);
      }
      if (next >= 0) {
        const std::int64_t wait = next - now_ns();
        timeout_ms = wait <= 0 ? 0 : static_cast<int>((wait + 999'999) / 1'000'000);
      }
    }
    const int n = ::epoll_wait(m.epoll_fd, events.data(), static_cast<int>(events.size()), timeout_ms);
    std::lock_guard lk(m.mu);
    const std::int64_t now = now_ns();
    for (int i = 0; i < n; ++i) {
      const int fd = events[static_cast<std::size_t>(i)].data.fd;
      if (fd == m.wake_fd) {
        std::uint64_t v;
        (void)!::read(m.wake_fd, &v, sizeof(v));
        continue;
      }
      if (fd == m.listen_fd) {
        for (;;) {
          const int c = ::accept4(m.listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
          if (c < 0) break;
          const int buf = 4 << 20;  // room for bursts: the receiving node drains at its rate
          ::setsockopt(c, SOL_SOCKET, SO_SNDBUF, &buf, sizeof(buf));
          epoll_event ev{};
          ev.events = EPOLLIN;
          ev.data.fd = c;
          ::epoll_ctl(m.epoll_fd, EPOLL_CTL_ADD, c, &ev);
          m.clients.push_back({c});
        }
        continue;
      }
      auto it = std::find_if(m.clients.begin(), m.clients.end(), [fd](const auto& c) { return c.fd == fd; });
      if (it == m.clients.end()) continue;
      const std::uint32_t revents = events[static_cast<std::size_t>(i)].events;
      if (revents & EPOLLOUT) flush(*it);
      bool closed = (revents & (EPOLLHUP | EPOLLERR)) != 0 && !(revents & EPOLLIN);
      for (int k = 0; k < 256 && m.reading && (revents & EPOLLIN); ++k) {  // bounded batch so one node cannot starve the others
        mockwire::Record r;
        const ssize_t got = ::recv(fd, &r, sizeof(r), MSG_DONTWAIT);
        if (got == 0) {
          closed = true;
          break;
        }
        if (got < 0) {
          if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) closed = true;
          break;
        }
        if (got != sizeof(r)) continue;  // malformed record: ignored
        if (r.kind == mockwire::kHello) {
          it->node = r.frame.can_id;
        } else if (r.kind == mockwire::kRestart) {
          if (it->bus_off) {
            it->bus_off = false;
            mockwire::Record e;
            e.frame = make_error_frame_for_state(BusState::error_active);
            e.timestamp_ns = now;
            send_to(*it, e);
          }
        } else {
          on_frame(*it, r, now);
        }
      }
      if (closed) {
        ::epoll_ctl(m.epoll_fd, EPOLL_CTL_DEL, fd, nullptr);
        ::close(fd);
        if (m.held && m.held->first == fd) m.held->first = -1;
        for (auto& d : m.delayed) {
          if (d.from_fd == fd) d.from_fd = -1;
        }
        m.clients.erase(it);
      }
    }
    for (std::uint32_t node : m.bus_off_requests) {
      for (auto& c : m.clients) {
        if (c.node == node && !c.bus_off) {
          c.bus_off = true;
          mockwire::Record e;
          e.frame = make_error_frame_for_state(BusState::bus_off);
          e.timestamp_ns = now;
          send_to(c, e);
        }
      }
    }
    m.bus_off_requests.clear();
    for (const CanFrame& f : m.error_injections) {
      mockwire::Record e;
      e.frame = f;
      e.timestamp_ns = now;
      broadcast(-1, e);
    }
    m.error_injections.clear();
    while (!m.delayed.empty() && m.delayed.front().due_ns <= now) {
      broadcast(m.delayed.front().from_fd, m.delayed.front().rec);
      m.delayed.erase(m.delayed.begin());
    }
    if (m.held && now - m.held_since >= 1'000'000) {
      broadcast(m.held->first, m.held->second);
      m.held.reset();
    }
    // Back-pressure: read from nodes only while no outbox is waiting (below its cap).
    bool blocked = false;
    const std::int64_t after = now_ns();
    for (auto& c : m.clients) {
      flush(c);
      if (!c.outbox.empty() && c.outbox.size() < Impl::kOutboxCap && after - c.progress_ns < Impl::kStallNs) {
        blocked = true;
      }
    }
    m.reading = !blocked;
    for (auto& c : m.clients) {
      set_events(c, (m.reading ? EPOLLIN : 0u) | (c.outbox.empty() ? 0u : static_cast<std::uint32_t>(EPOLLOUT)));
    }
    m.stats.nodes = static_cast<int>(std::count_if(m.clients.begin(), m.clients.end(),
                                                   [](const auto& c) { return c.node != 0xFFFFFFFFu; }));
  }
}

namespace {
volatile sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }
}  // namespace

int run_broker_until_signal(const MockCanBrokerConfig& cfg, const CanFaultConfig& faults) {
  struct sigaction sa{};
  sa.sa_handler = on_signal;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
  MockCanBroker broker(cfg);
  broker.set_faults(faults);
  while (!g_stop) ::usleep(20'000);
  return 0;
}

}  // namespace crease::drivers
