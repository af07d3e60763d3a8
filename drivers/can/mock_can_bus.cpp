#include "drivers/can/mock_can_bus.h"

#include <poll.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <new>
#include <stdexcept>

#include "drivers/can/mock_access.h"
#include "drivers/can/mock_wire.h"
#include "rt/clock.h"

namespace crease::drivers {
using rt::now_ns;

MockCanBus::MockCanBus(MockCanBusConfig cfg) : cfg_(std::move(cfg)) {
  auto fail = [this](const char* what, int e) {
    close_all();
    throw std::runtime_error("mock CAN bus '" + cfg_.bus + "': " + what + " (" + std::strerror(e) + ")");
  };
  const mockwire::BusAccess access = mockwire::make_bus_access(cfg_.group);
  sockaddr_un addr{};
  const socklen_t len = mockwire::make_address(cfg_.bus, addr);
  fd_ = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  if (fd_ < 0) fail("socket", errno);
  if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), len) != 0) fail("no broker", errno);
  // Anyone may bind a free abstract name: join only a broker of a user this node trusts.
  mockwire::PeerCred broker;
  if (!mockwire::peer_allowed(fd_, access, broker)) {
    close_all();
    throw std::runtime_error("mock CAN bus '" + cfg_.bus + "': not joining a broker of another user: " +
                             mockwire::describe_refusal(broker, access));
  }
  // The shared segment: created here, handed to the broker with the hello.
  const int shm_fd = ::memfd_create("crease-can-node", MFD_CLOEXEC);
  if (shm_fd < 0) fail("memfd_create", errno);
  void* p = MAP_FAILED;
  if (::fchmod(shm_fd, 0600) == 0 && ::ftruncate(shm_fd, sizeof(mockwire::NodeShm)) == 0) {
    p = ::mmap(nullptr, sizeof(mockwire::NodeShm), PROT_READ | PROT_WRITE, MAP_SHARED, shm_fd, 0);
  }
  if (p == MAP_FAILED) {
    const int e = errno;
    ::close(shm_fd);
    fail("shared memory", e);
  }
  shm_ = new (p) mockwire::NodeShm;
  mockwire::Record hello;
  hello.kind = mockwire::kHello;
  hello.frame.can_id = cfg_.node_id;
  const ssize_t sent = mockwire::send_record(fd_, hello, &shm_fd, 1, 0);
  const int send_errno = errno;
  ::close(shm_fd);
  if (sent != sizeof(hello)) {
    // A broker that refused this node may have hung up before the hello: its answer waits.
    mockwire::Record answer;
    int afds[mockwire::kMaxFds];
    ssize_t got = mockwire::recv_record(fd_, answer, afds, MSG_DONTWAIT);
    if (got < 0 && errno == ECONNRESET) got = mockwire::recv_record(fd_, answer, afds, MSG_DONTWAIT);
    const bool refused = got == sizeof(answer) && answer.kind == mockwire::kRefused;
    for (int fd : afds) {
      if (fd >= 0) ::close(fd);
    }
    if (refused) fail("the broker refuses this user (another user's bus; see its group)", EACCES);
    fail("hello", send_errno);
  }
  // The welcome: the broker thread's eventfd and its page.
  pollfd pfd{fd_, POLLIN, 0};
  if (::poll(&pfd, 1, 5000) <= 0) fail("no welcome from the broker", ETIMEDOUT);
  mockwire::Record welcome;
  int fds[mockwire::kMaxFds];
  ssize_t got = mockwire::recv_record(fd_, welcome, fds, 0);
  // A broker that hung up on an unread hello leaves ECONNRESET, reported before its answer.
  if (got < 0 && errno == ECONNRESET) got = mockwire::recv_record(fd_, welcome, fds, MSG_DONTWAIT);
  const int recv_errno = errno;
  if (got == sizeof(welcome) && welcome.kind == mockwire::kRefused) {
    fail("the broker refuses this user (another user's bus; see its group)", EACCES);
  }
  if (got != sizeof(welcome) || welcome.kind != mockwire::kWelcome || fds[0] < 0 || fds[1] < 0) {
    for (int fd : fds) {
      if (fd >= 0) ::close(fd);
    }
    fail("bad welcome from the broker", got < 0 ? recv_errno : EPROTO);
  }
  doorbell_fd_ = fds[0];
  void* page = ::mmap(nullptr, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, fds[1], 0);
  const int map_errno = errno;
  ::close(fds[1]);
  if (page == MAP_FAILED) fail("broker page", map_errno);
  reactor_ = static_cast<mockwire::ReactorShm*>(page);
}

void MockCanBus::close_all() noexcept {
  if (shm_) ::munmap(shm_, sizeof(mockwire::NodeShm));
  if (reactor_) ::munmap(reactor_, 4096);
  if (doorbell_fd_ >= 0) ::close(doorbell_fd_);
  if (fd_ >= 0) ::close(fd_);
  shm_ = nullptr;
  reactor_ = nullptr;
  doorbell_fd_ = fd_ = -1;
}

MockCanBus::~MockCanBus() { close_all(); }

void MockCanBus::wake_broker() noexcept {
  // The ring index was stored seq_cst; the broker thread stores `sleeping` then reads the
  // rings, both seq_cst: one of us sees the other.
  if (reactor_->sleeping.load(std::memory_order_seq_cst) != 0 && reactor_->sleeping.exchange(0) != 0) {
    const std::uint64_t one = 1;
    (void)!::write(doorbell_fd_, &one, sizeof(one));
    ++broker_wakeups_;
  }
}

void MockCanBus::note_sent(const CanFrame& f, std::int64_t now) noexcept {
  if (cfg_.nominal_bps != 0) {
    const std::int64_t start = tx_free_at_ > now ? tx_free_at_ : now;
    tx_free_at_ = start + can_frame_time_ns(f, cfg_.nominal_bps, cfg_.data_bps);
    tx_done_[static_cast<std::size_t>(tx_head_)] = tx_free_at_;
    tx_head_ = (tx_head_ + 1) % kTxQueueLen;
  }
  ++counters_.tx_frames;
}

std::size_t MockCanBus::send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept {
  if (state_ == BusState::bus_off) {
    if (last) *last = SendResult::bus_off;
    return 0;
  }
  const std::int64_t now = now_ns();
  // How many fit in the modelled tx queue (frame n takes the slot the oldest queued frame
  // frees) and in the ring to the broker.
  const std::size_t ring_free = shm_->tx.free_slots();
  std::size_t n = 0;
  for (; n < frames.size() && n < ring_free; ++n) {
    if (cfg_.nominal_bps != 0) {
      if (n >= static_cast<std::size_t>(kTxQueueLen)) break;
      const std::size_t slot = static_cast<std::size_t>((tx_head_ + static_cast<int>(n)) % kTxQueueLen);
      if (tx_done_[slot] > now) break;
    }
  }
  // Publish in chunks with one index update each (only this node pushes; room checked).
  for (std::size_t done = 0; done < n;) {
    mockwire::Record recs[16];
    const std::size_t m = std::min<std::size_t>(16, n - done);
    for (std::size_t k = 0; k < m; ++k) {
      recs[k].kind = mockwire::kData;
      recs[k].node = cfg_.node_id;
      recs[k].timestamp_ns = now;  // node -> broker: when it was sent
      recs[k].frame = frames[done + k];
      note_sent(frames[done + k], now);
    }
    shm_->tx.push_n(recs, static_cast<std::uint32_t>(m));
    done += m;
  }
  if (n > 0) wake_broker();
  SendResult result = SendResult::ok;
  if (n < frames.size()) {
    ++counters_.tx_no_buffers;
    errno_ = ENOBUFS;
    result = SendResult::no_buffers;
  }
  if (last) *last = result;
  return n;
}

SendResult MockCanBus::send(const CanFrame& f) noexcept {
  SendResult r = SendResult::ok;
  (void)send_batch({&f, 1}, &r);
  return r;
}

bool MockCanBus::rearm_rx() noexcept {
  // Take every doorbell (1-byte records) off the socket, then clear the flag: a record the
  // broker pushes after the clear rings a new doorbell; one pushed before is seen by the
  // caller's second look at the ring.
  char bytes[8];
  iovec iov[8];
  mmsghdr msgs[8];
  for (;;) {
    for (int k = 0; k < 8; ++k) {
      iov[k] = {&bytes[k], 1};
      msgs[k] = {};
      msgs[k].msg_hdr.msg_iov = &iov[k];
      msgs[k].msg_hdr.msg_iovlen = 1;
    }
    const int got = ::recvmmsg(fd_, msgs, 8, MSG_DONTWAIT, nullptr);
    if (got < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) break;
      errno_ = errno;
      return false;
    }
    for (int k = 0; k < got; ++k) {
      if (msgs[k].msg_len == 0) {
        errno_ = EPIPE;  // the broker is gone
        return false;
      }
    }
    if (got < 8) break;
  }
  shm_->rx_signalled.store(0, std::memory_order_seq_cst);  // then the caller reads the ring (seq_cst)
  return true;
}

RecvResult MockCanBus::try_receive(RxFrame& out) noexcept {
  mockwire::Record r;
  if (!shm_->rx.try_pop(r)) {
    if (!rx_empty_once_) {
      rx_empty_once_ = true;  // report empty once without a system call
      return RecvResult::empty;
    }
    if (!rearm_rx()) return RecvResult::error;
    if (!shm_->rx.try_pop(r)) return RecvResult::empty;
  }
  rx_empty_once_ = false;
  if (shm_->rx_need_space.load(std::memory_order_seq_cst) != 0 && shm_->rx.size() <= mockwire::kRxRing / 2 &&
      shm_->rx_need_space.exchange(0) != 0) {
    wake_broker();  // the broker holds records for this ring, which is half empty now
  }
  out.frame = r.frame;
  out.timestamp_ns = r.timestamp_ns;
  return account_received(r.frame, state_, counters_);
}

void MockCanBus::restart() noexcept {
  mockwire::Record r;
  r.kind = mockwire::kRestart;
  r.node = cfg_.node_id;
  if (shm_->tx.try_push(r)) {
    wake_broker();
    state_ = BusState::error_active;
    tx_done_.fill(0);
    tx_free_at_ = 0;
  } else {
    errno_ = ENOBUFS;
  }
}

}  // namespace crease::drivers
