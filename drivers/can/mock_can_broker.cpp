#include "drivers/can/mock_can_broker.h"

#include <fcntl.h>
#include <linux/can/error.h>
#include <signal.h>
#include <sys/epoll.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

#include "drivers/can/mock_access.h"
#include "drivers/can/mock_reactor.h"
#include "drivers/can/mock_wire.h"

namespace crease::drivers {
namespace {

using rt::now_ns;
using mockwire::Record;

[[noreturn]] void fail(const std::string& bus, const char* what) {
  throw std::runtime_error("mock CAN bus '" + bus + "': " + what + ": " + std::strerror(errno));
}

constexpr std::uint32_t kNoNode = 0xFFFFFFFFu;

}  // namespace

// The broker's state; the process's reactor thread drives it (mockwire::BrokerCore).
struct MockCanBroker::Impl final : mockwire::BrokerCore {
  MockCanBrokerConfig cfg;
  mockwire::BusAccess access;
  std::shared_ptr<mockwire::Reactor> reactor;
  int listen_fd = -1;

  struct Client {
    int fd = -1;
    std::uint32_t node = kNoNode;
    bool bus_off = false;
    mockwire::NodeShm* shm = nullptr;  // mapped after the hello
    std::deque<Record> outbox;          // records its rx ring did not take yet
    std::int64_t progress_ns = 0;       // last time its outbox started or moved
    bool pushed = false;                // its rx ring got records this tick (doorbell due)
  };
  // A node whose rx ring is full gets an outbox; while an outbox is non-empty and draining
  // (it moved within kStallNs) the broker stops reading from nodes: back-pressure reaches the
  // senders as no_buffers instead of frames being lost. A node that stops reading for longer
  // no longer holds the bus up: its outbox fills to the cap and then it loses its own frames
  // (counted as rx_overflow), like a CAN socket's receive queue.
  static constexpr std::size_t kOutboxCap = 4096;
  static constexpr std::int64_t kStallNs = 100'000'000;  // a reader paused by the scheduler is not idle
  static constexpr int kReadBatch = 256;                 // per node per tick: nobody starves the others
  bool reading = true;
  std::vector<std::unique_ptr<Client>> clients;

  struct Delayed {
    std::int64_t due_ns;
    std::uint64_t order;
    int from_fd;
    Record rec;
  };
  std::vector<Delayed> delayed;  // kept sorted by (due_ns, order)
  std::uint64_t order = 0;
  std::optional<std::pair<int, Record>> held;  // reorder fault
  std::int64_t held_since = 0;
  std::int64_t bus_free_at = 0;

  mutable std::mutex mu;  // guards everything below (set by user threads)
  CanFaultConfig faults;
  std::mt19937_64 rng{1};
  std::vector<std::uint32_t> silent;
  std::vector<std::uint32_t> bus_off_requests;
  std::vector<CanFrame> error_injections;
  MockCanBrokerStats stats;

  ~Impl() override {
    for (auto& c : clients) drop_client(*c);
    if (listen_fd >= 0) ::close(listen_fd);
  }

  static void drop_client(Client& c) {
    ::close(c.fd);
    if (c.shm) ::munmap(c.shm, sizeof(mockwire::NodeShm));
    c.shm = nullptr;
  }

  // --- delivery -------------------------------------------------------------------------
  void send_to(Client& c, const Record& r) {
    if (!c.shm) return;
    if (c.outbox.empty() && c.shm->rx.try_push(r)) {
      ++stats.forwarded;
      c.pushed = true;
      return;
    }
    if (c.outbox.size() >= kOutboxCap) {
      ++stats.rx_overflow;
      return;
    }
    if (c.outbox.empty()) c.progress_ns = now_ns();
    c.outbox.push_back(r);
  }
  void flush(Client& c) {
    while (!c.outbox.empty() && c.shm->rx.try_push(c.outbox.front())) {
      ++stats.forwarded;
      c.outbox.pop_front();
      c.progress_ns = now_ns();
      c.pushed = true;
    }
    // Ask the node to wake us when it makes room (checked again before the reactor sleeps).
    c.shm->rx_need_space.store(c.outbox.empty() ? 0u : 1u, std::memory_order_seq_cst);
  }
  // Makes the node's socket readable if its rx ring got records and no doorbell is pending.
  void ring_doorbell(Client& c) {
    c.pushed = false;
    if (c.shm->rx_signalled.exchange(1, std::memory_order_seq_cst) == 0) {
      const char b = 1;
      (void)!::send(c.fd, &b, 1, MSG_DONTWAIT | MSG_NOSIGNAL);
    }
  }
  void broadcast(int from_fd, const Record& r) {
    for (auto& c : clients) {
      if (c->fd != from_fd && c->node != kNoNode) send_to(*c, r);
    }
  }
  // Bus-time model: the frame occupies the virtual bus after the previous one finished.
  void bus_time(Record& r, std::int64_t now) {
    if (cfg.nominal_bps == 0) {
      r.timestamp_ns = now;
      return;
    }
    const std::int64_t dt = can_frame_time_ns(r.frame, cfg.nominal_bps, cfg.data_bps);
    const std::int64_t start = std::max(now, bus_free_at);
    bus_free_at = start + dt;
    stats.busy_ns += dt;
    r.timestamp_ns = bus_free_at;
  }
  void schedule(int from_fd, const Record& r, std::int64_t due) {
    Delayed d{due, order++, from_fd, r};
    auto it = std::upper_bound(delayed.begin(), delayed.end(), d, [](const auto& a, const auto& b) {
      return a.due_ns < b.due_ns || (a.due_ns == b.due_ns && a.order < b.order);
    });
    delayed.insert(it, d);
  }
  // One frame from a node: apply faults (mu held), then forward.
  void on_frame(Client& from, Record r, std::int64_t now) {
    ++stats.received;
    r.node = from.node;
    const auto& f = faults;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (from.bus_off || std::find(silent.begin(), silent.end(), from.node) != silent.end()) {
      ++stats.dropped_fault;
      return;
    }
    if (f.error_frame > 0 && u(rng) < f.error_frame) {
      Record e;
      e.frame.can_id = CAN_ERR_FLAG | CAN_ERR_PROT | CAN_ERR_BUSERROR;
      e.frame.len = CAN_ERR_DLC;
      e.timestamp_ns = now;
      broadcast(-1, e);
    }
    if (f.drop > 0 && u(rng) < f.drop) {
      ++stats.dropped_fault;
      return;
    }
    if (f.corrupt > 0 && u(rng) < f.corrupt && r.frame.len > 0) {
      const std::uint32_t bit = static_cast<std::uint32_t>(rng() % (8u * r.frame.len));
      r.frame.data[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    }
    bus_time(r, now);
    const int copies = (f.duplicate > 0 && u(rng) < f.duplicate) ? 2 : 1;
    if (f.delay > 0 && u(rng) < f.delay) {
      for (int i = 0; i < copies; ++i) schedule(from.fd, r, now + f.delay_ns);
      return;
    }
    if (f.reorder > 0 && !held && u(rng) < f.reorder) {
      held.emplace(from.fd, r);
      held_since = now;
      return;
    }
    for (int i = 0; i < copies; ++i) {
      if (cfg.pace && r.timestamp_ns > now) {
        schedule(from.fd, r, r.timestamp_ns);
      } else {
        broadcast(from.fd, r);
      }
    }
    if (held) {
      broadcast(held->first, held->second);
      held.reset();
    }
  }

  // --- sockets ----------------------------------------------------------------------------
  // A node of another user: told so, hung up on, counted and logged (the first 20 refusals,
  // then every 1000th, so a refused peer cannot flood the log).
  void refuse(int fd, const mockwire::PeerCred& who) {
    Record r;
    r.kind = mockwire::kRefused;
    (void)mockwire::send_record(fd, r, nullptr, 0, MSG_DONTWAIT);
    ::close(fd);
    const std::uint64_t n = ++stats.refused;
    if (n <= 20 || n % 1000 == 0) {
      std::fprintf(stderr, "crease: mock CAN bus '%s': refused connection %llu: %s\n", cfg.name.c_str(),
                   static_cast<unsigned long long>(n), mockwire::describe_refusal(who, access).c_str());
    }
  }
  void accept_all() {
    for (;;) {
      const int c = ::accept4(listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (c < 0) break;
      mockwire::PeerCred who;
      if (!mockwire::peer_allowed(c, access, who)) {
        refuse(c, who);
        continue;
      }
      clients.push_back(std::make_unique<Client>());
      clients.back()->fd = c;
      reactor->watch_locked(this, c);
    }
  }
  // The hello: maps the node's segment and answers with the reactor's eventfd and page.
  bool on_hello(Client& c, const Record& r, int shm_fd) {
    if (shm_fd < 0 || c.shm) return false;
    struct stat st{};
    void* p = MAP_FAILED;
    if (::fstat(shm_fd, &st) == 0 && st.st_size >= static_cast<off_t>(sizeof(mockwire::NodeShm))) {
      p = ::mmap(nullptr, sizeof(mockwire::NodeShm), PROT_READ | PROT_WRITE, MAP_SHARED, shm_fd, 0);
    }
    ::close(shm_fd);
    if (p == MAP_FAILED) return false;
    auto* shm = static_cast<mockwire::NodeShm*>(p);
    if (shm->magic != mockwire::kShmMagic || shm->size != sizeof(mockwire::NodeShm)) {
      ::munmap(p, sizeof(mockwire::NodeShm));
      return false;
    }
    c.shm = shm;
    Record w;
    w.kind = mockwire::kWelcome;
    const int fds[2] = {reactor->doorbell_fd(), reactor->page_fd()};
    if (mockwire::send_record(c.fd, w, fds, 2, MSG_DONTWAIT) != sizeof(w)) return false;
    c.node = r.frame.can_id;
    return true;
  }
  void remove_client(int fd) {
    auto it = std::find_if(clients.begin(), clients.end(), [fd](const auto& c) { return c->fd == fd; });
    if (it == clients.end()) return;
    reactor->unwatch_locked(fd);
    if (held && held->first == fd) held->first = -1;
    for (auto& d : delayed) {
      if (d.from_fd == fd) d.from_fd = -1;
    }
    drop_client(**it);
    clients.erase(it);
  }

  void on_fd(int fd, std::uint32_t ev, std::int64_t now) override {
    std::lock_guard lk(mu);
    if (fd == listen_fd) {
      accept_all();
      return;
    }
    auto it = std::find_if(clients.begin(), clients.end(), [fd](const auto& c) { return c->fd == fd; });
    if (it == clients.end()) return;
    Client& c = **it;
    bool closed = (ev & (EPOLLHUP | EPOLLERR)) != 0 && !(ev & EPOLLIN);
    for (int k = 0; k < 16 && (ev & EPOLLIN); ++k) {
      Record r;
      int fds[mockwire::kMaxFds];
      const ssize_t got = mockwire::recv_record(fd, r, fds, MSG_DONTWAIT);
      if (fds[1] >= 0) ::close(fds[1]);  // a hello carries one descriptor
      if (got == 0) {
        closed = true;
        break;
      }
      if (got < 0) {
        if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) closed = true;
        break;
      }
      const int shm_fd = fds[0];
      if (got == sizeof(r) && r.kind == mockwire::kHello) {
        if (!on_hello(c, r, shm_fd)) closed = true;
      } else if (shm_fd >= 0) {
        ::close(shm_fd);  // malformed: ignored
      }
    }
    if (closed) {
      // What the node sent before it hung up still goes out, as a CAN controller transmits
      // the frames already queued when a socket closes.
      std::int64_t first_sent = now;
      (void)read_tx(c, now, static_cast<int>(mockwire::kTxRing), first_sent);
      remove_client(fd);
    }
    stats.nodes = static_cast<int>(std::count_if(clients.begin(), clients.end(), [](const auto& x) { return x->node != kNoNode; }));
  }

  // --- the tick -----------------------------------------------------------------------------
  // Takes up to `max` records off a node's tx ring onto the bus; lowers `first_sent` to the
  // earliest send time among them. True if any moved.
  bool read_tx(Client& c, std::int64_t now, int max, std::int64_t& first_sent) {
    if (!c.shm) return false;
    bool moved = false;
    Record r;
    for (int k = 0; k < max && c.shm->tx.try_pop(r); ++k) {
      moved = true;
      if (r.timestamp_ns > 0 && r.timestamp_ns < first_sent) first_sent = r.timestamp_ns;
      if (r.kind == mockwire::kRestart) {
        if (c.bus_off) {
          c.bus_off = false;
          Record e;
          e.frame = make_error_frame_for_state(BusState::error_active);
          e.timestamp_ns = now;
          send_to(c, e);
        }
      } else if (r.kind == mockwire::kData) {
        on_frame(c, r, now);
      }
    }
    return moved;
  }

  std::int64_t tick(std::int64_t now) override {
    std::lock_guard lk(mu);
    const std::uint64_t forwarded_before = stats.forwarded, received_before = stats.received;
    bool moved = false;
    std::int64_t first_sent = now;  // nodes stamp their send time on the records
    for (std::size_t i = 0; i < clients.size() && reading; ++i) {
      if (read_tx(*clients[i], now, kReadBatch, first_sent)) moved = true;
    }
    for (std::uint32_t node : bus_off_requests) {
      for (auto& c : clients) {
        if (c->node == node && !c->bus_off) {
          c->bus_off = true;
          Record e;
          e.frame = make_error_frame_for_state(BusState::bus_off);
          e.timestamp_ns = now;
          send_to(*c, e);
        }
      }
    }
    bus_off_requests.clear();
    for (const CanFrame& f : error_injections) {
      Record e;
      e.frame = f;
      e.timestamp_ns = now;
      broadcast(-1, e);
    }
    error_injections.clear();
    while (!delayed.empty() && delayed.front().due_ns <= now) {
      broadcast(delayed.front().from_fd, delayed.front().rec);
      delayed.erase(delayed.begin());
    }
    if (held && now - held_since >= 1'000'000) {
      broadcast(held->first, held->second);
      held.reset();
    }
    // Back-pressure: read from nodes only while no outbox is waiting (below its cap).
    bool blocked = false;
    const std::int64_t after = now_ns();
    for (auto& cp : clients) {
      Client& c = *cp;
      if (!c.shm) continue;
      if (!c.outbox.empty() || c.shm->rx_need_space.load(std::memory_order_relaxed)) flush(c);
      if (!c.outbox.empty() && c.outbox.size() < kOutboxCap && after - c.progress_ns < kStallNs) blocked = true;
      if (c.pushed) ring_doorbell(c);
    }
    reading = !blocked;
    const bool any = moved || stats.forwarded != forwarded_before || stats.received != received_before;
    return any ? first_sent : -1;
  }

  bool pending() const noexcept override {
    for (const auto& cp : clients) {
      const Client& c = *cp;
      if (!c.shm) continue;
      if (reading && !c.shm->tx.empty()) return true;
      if (!c.outbox.empty() && c.shm->rx.free_slots() >= mockwire::kRxRing / 2) return true;
    }
    return false;
  }

  std::int64_t next_deadline_ns() const override {
    std::lock_guard lk(mu);
    std::int64_t next = -1;
    auto take = [&next](std::int64_t t) { next = next < 0 ? t : std::min(next, t); };
    if (!delayed.empty()) take(delayed.front().due_ns);
    if (held) take(held_since + 1'000'000);
    if (!bus_off_requests.empty() || !error_injections.empty()) take(0);
    for (const auto& c : clients) {
      if (!c->outbox.empty()) take(now_ns() + 1'000'000);  // safety net besides the node's wake
    }
    if (!reading) take(now_ns() + kStallNs);  // re-check stalled outboxes
    return next;
  }
};

MockCanBroker::MockCanBroker(MockCanBrokerConfig cfg) : cfg_(std::move(cfg)), impl_(new Impl) {
  impl_->cfg = cfg_;
  try {
    impl_->access = mockwire::make_bus_access(cfg_.group);
  } catch (...) {
    delete impl_;
    throw;
  }
  sockaddr_un addr{};
  socklen_t len = 0;
  try {
    len = mockwire::make_address(cfg_.name, addr);
    impl_->listen_fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (impl_->listen_fd < 0) fail(cfg_.name, "socket");
    if (::bind(impl_->listen_fd, reinterpret_cast<sockaddr*>(&addr), len) != 0) {
      fail(cfg_.name, "bind (is another broker serving this bus?)");
    }
    ::listen(impl_->listen_fd, 64);
    impl_->reactor = mockwire::Reactor::instance();
  } catch (...) {
    delete impl_;
    throw;
  }
  impl_->reactor->attach(impl_, impl_->listen_fd);
}

MockCanBroker::~MockCanBroker() {
  impl_->reactor->detach(impl_);
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
  impl_->reactor->wake();
}

void MockCanBroker::inject_error_frame(const CanFrame& err) {
  {
    std::lock_guard lk(impl_->mu);
    impl_->error_injections.push_back(err);
  }
  impl_->reactor->wake();
}

MockCanBrokerStats MockCanBroker::stats() const {
  std::lock_guard lk(impl_->mu);
  return impl_->stats;
}

int MockCanBroker::connected_nodes() const { return stats().nodes; }

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
