#include "drivers/can/mock_can_bus.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "drivers/can/mock_wire.h"

namespace crease::drivers {
namespace {
std::int64_t now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}
}  // namespace

MockCanBus::MockCanBus(MockCanBusConfig cfg) : cfg_(std::move(cfg)) {
  sockaddr_un addr{};
  const socklen_t len = mockwire::make_address(cfg_.bus, addr);
  fd_ = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error("mock CAN bus '" + cfg_.bus + "': socket: " + std::strerror(errno));
  if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), len) != 0) {
    const int e = errno;
    ::close(fd_);
    throw std::runtime_error("mock CAN bus '" + cfg_.bus + "': no broker (" + std::strerror(e) + ")");
  }
  mockwire::Record hello;
  hello.kind = mockwire::kHello;
  hello.frame.can_id = cfg_.node_id;
  if (::send(fd_, &hello, sizeof(hello), MSG_NOSIGNAL) != sizeof(hello)) {
    const int e = errno;
    ::close(fd_);
    throw std::runtime_error("mock CAN bus '" + cfg_.bus + "': hello: " + std::strerror(e));
  }
}

MockCanBus::~MockCanBus() { ::close(fd_); }

bool MockCanBus::tx_queue_full(std::int64_t now) const noexcept {
  // The oldest queued frame must have left the (virtual) controller.
  return cfg_.nominal_bps != 0 && tx_done_[static_cast<std::size_t>(tx_head_)] > now;
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
  constexpr std::size_t kMax = 16;
  if (state_ == BusState::bus_off) {
    if (last) *last = SendResult::bus_off;
    return 0;
  }
  std::size_t done = 0;
  SendResult result = SendResult::ok;
  while (done < frames.size() && result == SendResult::ok) {
    const std::int64_t now = now_ns();
    mockwire::Record recs[kMax];
    iovec iov[kMax];
    mmsghdr msgs[kMax];
    // How many fit in the modelled tx queue (each frame occupies the slot it will free).
    std::size_t n = 0;
    std::int64_t free_at = tx_free_at_;
    for (; n < kMax && done + n < frames.size(); ++n) {
      if (cfg_.nominal_bps != 0) {
        const std::size_t slot = static_cast<std::size_t>((tx_head_ + static_cast<int>(n)) % kTxQueueLen);
        if (n >= static_cast<std::size_t>(kTxQueueLen) || tx_done_[slot] > now) break;
        free_at = (free_at > now ? free_at : now) + can_frame_time_ns(frames[done + n], cfg_.nominal_bps, cfg_.data_bps);
      }
      recs[n].kind = mockwire::kData;
      recs[n].node = cfg_.node_id;
      recs[n].timestamp_ns = 0;
      recs[n].frame = frames[done + n];
      iov[n] = {&recs[n], sizeof(mockwire::Record)};
      msgs[n] = {};
      msgs[n].msg_hdr.msg_iov = &iov[n];
      msgs[n].msg_hdr.msg_iovlen = 1;
    }
    if (n == 0) {
      ++counters_.tx_no_buffers;
      errno_ = ENOBUFS;
      result = SendResult::no_buffers;
      break;
    }
    const int sent = ::sendmmsg(fd_, msgs, static_cast<unsigned>(n), MSG_DONTWAIT | MSG_NOSIGNAL);
    if (sent < 0) {
      errno_ = errno;
      result = (errno_ == EAGAIN || errno_ == EWOULDBLOCK || errno_ == ENOBUFS) ? SendResult::no_buffers : SendResult::error;
      if (result == SendResult::no_buffers) ++counters_.tx_no_buffers;
      break;
    }
    for (int k = 0; k < sent; ++k) note_sent(frames[done + static_cast<std::size_t>(k)], now);
    done += static_cast<std::size_t>(sent);
    if (static_cast<std::size_t>(sent) < n) {
      ++counters_.tx_no_buffers;
      errno_ = EAGAIN;
      result = SendResult::no_buffers;
    }
  }
  if (last) *last = result;
  return done;
}

SendResult MockCanBus::send(const CanFrame& f) noexcept {
  if (state_ == BusState::bus_off) return SendResult::bus_off;
  const std::int64_t now = now_ns();
  if (tx_queue_full(now)) {
    ++counters_.tx_no_buffers;
    errno_ = ENOBUFS;
    return SendResult::no_buffers;
  }
  mockwire::Record r;
  r.kind = mockwire::kData;
  r.node = cfg_.node_id;
  r.frame = f;
  const ssize_t n = ::send(fd_, &r, sizeof(r), MSG_DONTWAIT | MSG_NOSIGNAL);
  if (n != sizeof(r)) {
    errno_ = errno;
    if (errno_ == EAGAIN || errno_ == EWOULDBLOCK || errno_ == ENOBUFS) {
      ++counters_.tx_no_buffers;
      return SendResult::no_buffers;
    }
    return SendResult::error;
  }
  note_sent(f, now);
  return SendResult::ok;
}

RecvResult MockCanBus::try_receive(RxFrame& out) noexcept {
  if (rx_pos_ == rx_count_) {
    if (rx_partial_) {
      // The last refill took everything that was queued: report empty once without a system
      // call, so a cyclic reader costs one recvmmsg() per cycle. The next call asks again.
      rx_partial_ = false;
      return RecvResult::empty;
    }
    // Refill: one recvmmsg() takes up to kRxBatch records.
    iovec iov[kRxBatch];
    mmsghdr msgs[kRxBatch];
    for (int k = 0; k < kRxBatch; ++k) {
      iov[k] = {rx_records_[k], sizeof(mockwire::Record)};
      msgs[k] = {};
      msgs[k].msg_hdr.msg_iov = &iov[k];
      msgs[k].msg_hdr.msg_iovlen = 1;
    }
    const int got = ::recvmmsg(fd_, msgs, kRxBatch, MSG_DONTWAIT, nullptr);
    if (got < 0) {
      errno_ = errno;
      return (errno_ == EAGAIN || errno_ == EWOULDBLOCK || errno_ == EINTR) ? RecvResult::empty
                                                                             : RecvResult::error;
    }
    for (int k = 0; k < got; ++k) {
      if (msgs[k].msg_len != sizeof(mockwire::Record) || (msgs[k].msg_hdr.msg_flags & MSG_TRUNC)) {
        errno_ = msgs[k].msg_len == 0 ? EPIPE : EPROTO;  // broker gone, or a record of the wrong size
        return RecvResult::error;
      }
    }
    if (got == 0) {
      errno_ = EPIPE;
      return RecvResult::error;
    }
    rx_pos_ = 0;
    rx_count_ = got;
    rx_partial_ = got < kRxBatch;
  }
  mockwire::Record r;
  std::memcpy(&r, rx_records_[rx_pos_++], sizeof(r));
  out.frame = r.frame;
  out.timestamp_ns = r.timestamp_ns;
  if (r.frame.is_error()) {
    const BusState before = state_;
    state_ = bus_state_after_error_frame(state_, r.frame);
    if (state_ == BusState::bus_off && before != BusState::bus_off) ++counters_.bus_off_events;
    ++counters_.rx_error_frames;
    return RecvResult::error_frame;
  }
  ++counters_.rx_frames;
  return RecvResult::frame;
}

void MockCanBus::restart() noexcept {
  mockwire::Record r;
  r.kind = mockwire::kRestart;
  r.node = cfg_.node_id;
  if (::send(fd_, &r, sizeof(r), MSG_DONTWAIT | MSG_NOSIGNAL) == sizeof(r)) {
    state_ = BusState::error_active;
    tx_done_.fill(0);
    tx_free_at_ = 0;
  } else {
    errno_ = errno;
  }
}

}  // namespace crease::drivers
