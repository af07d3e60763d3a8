#include "drivers/can/socket_can_bus.h"

#include <linux/can/error.h>
#include <linux/can/netlink.h>
#include <linux/can/raw.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <system_error>

#include "rt/clock.h"

namespace crease::drivers {
namespace {
[[noreturn]] void fail(const std::string& ifname, const char* what, int e) {
  throw std::system_error(e, std::generic_category(), "SocketCAN '" + ifname + "': " + what);
}

std::int64_t real_now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}
}  // namespace

bool SocketCanBus::available(std::string* reason) {
  const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (s < 0) {
    if (reason) *reason = std::string("socket(PF_CAN, SOCK_RAW, CAN_RAW) failed: ") + std::strerror(errno);
    return false;
  }
  ::close(s);
  return true;
}

SocketCanBus::SocketCanBus(const SocketCanConfig& cfg) : ifname_(cfg.interface) {
  fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) fail(ifname_, "socket(PF_CAN)", errno);
  auto close_and_fail = [&](const char* what) {
    const int e = errno;
    ::close(fd_);
    fail(ifname_, what, e);
  };
  if (ifname_.empty() || ifname_.size() >= IFNAMSIZ) {
    errno = EINVAL;
    close_and_fail("interface name");
  }
  ifindex_ = static_cast<int>(::if_nametoindex(ifname_.c_str()));
  if (ifindex_ == 0) close_and_fail("no such interface");
  if (cfg.fd) {
    const int on = 1;
    if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof(on)) != 0) {
      close_and_fail("CAN_RAW_FD_FRAMES (interface not FD capable?)");
    }
    fd_enabled_ = true;
  }
  if (!cfg.filters.empty()) {
    std::vector<can_filter> f(cfg.filters.size());
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = {cfg.filters[i].id, cfg.filters[i].mask};
    if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, f.data(),
                     static_cast<socklen_t>(f.size() * sizeof(can_filter))) != 0) {
      close_and_fail("CAN_RAW_FILTER");
    }
  }
  const can_err_mask_t err_mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_PROT | CAN_ERR_TRX |
                                  CAN_ERR_ACK | CAN_ERR_BUSOFF | CAN_ERR_BUSERROR | CAN_ERR_RESTARTED;
  if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask)) != 0) {
    close_and_fail("CAN_RAW_ERR_FILTER");
  }
  const int own = cfg.loopback_own ? 1 : 0;
  ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof(own));
  const int on = 1;
  if (::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof(on)) != 0) close_and_fail("SO_TIMESTAMPNS");
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifindex_;
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) close_and_fail("bind");
}

SocketCanBus::~SocketCanBus() { ::close(fd_); }

SendResult SocketCanBus::send(const CanFrame& f) noexcept {
  if (state_ == BusState::bus_off) return SendResult::bus_off;
  if (f.is_fd() && !fd_enabled_) {
    errno_ = EINVAL;
    return SendResult::error;
  }
  const std::size_t n = f.mtu();
  const ssize_t w = ::write(fd_, &f, n);
  if (w == static_cast<ssize_t>(n)) {
    ++counters_.tx_frames;
    return SendResult::ok;
  }
  errno_ = w < 0 ? errno : EIO;
  if (errno_ == ENOBUFS || errno_ == EAGAIN || errno_ == EWOULDBLOCK) {
    ++counters_.tx_no_buffers;  // tx queue full: back-pressure, the caller retries next cycle
    return SendResult::no_buffers;
  }
  if (errno_ == ENETDOWN) {
    state_ = BusState::stopped;
  }
  return SendResult::error;
}

std::size_t SocketCanBus::send_batch(std::span<const CanFrame> frames, SendResult* last) noexcept {
  constexpr std::size_t kMax = 16;
  SendResult result = SendResult::ok;
  std::size_t done = 0;
  while (done < frames.size() && result == SendResult::ok) {
    if (state_ == BusState::bus_off) {
      result = SendResult::bus_off;
      break;
    }
    iovec iov[kMax];
    mmsghdr msgs[kMax];
    std::size_t n = 0;
    for (; n < kMax && done + n < frames.size(); ++n) {
      const CanFrame& f = frames[done + n];
      if (f.is_fd() && !fd_enabled_) break;
      iov[n] = {const_cast<CanFrame*>(&f), f.mtu()};
      msgs[n] = {};
      msgs[n].msg_hdr.msg_iov = &iov[n];
      msgs[n].msg_hdr.msg_iovlen = 1;
    }
    if (n == 0) {  // an FD frame on a classic socket
      errno_ = EINVAL;
      result = SendResult::error;
      break;
    }
    const int sent = ::sendmmsg(fd_, msgs, static_cast<unsigned>(n), MSG_DONTWAIT);
    if (sent < 0) {
      errno_ = errno;
      if (errno_ == ENOBUFS || errno_ == EAGAIN || errno_ == EWOULDBLOCK) {
        ++counters_.tx_no_buffers;
        result = SendResult::no_buffers;
      } else {
        if (errno_ == ENETDOWN) state_ = BusState::stopped;
        result = SendResult::error;
      }
      break;
    }
    counters_.tx_frames += static_cast<std::uint64_t>(sent);
    done += static_cast<std::size_t>(sent);
    if (static_cast<std::size_t>(sent) < n) {  // the kernel stopped at a full queue
      ++counters_.tx_no_buffers;
      errno_ = ENOBUFS;
      result = SendResult::no_buffers;
    }
  }
  if (last) *last = result;
  return done;
}

RecvResult SocketCanBus::try_receive(RxFrame& out) noexcept {
  iovec iov{&out.frame, sizeof(CanFrame)};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof(control);
  const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
  if (n < 0) {
    errno_ = errno;
    return (errno_ == EAGAIN || errno_ == EWOULDBLOCK || errno_ == EINTR) ? RecvResult::empty : RecvResult::error;
  }
  if (n == static_cast<ssize_t>(CAN_MTU)) {
    out.frame.flags = 0;  // classic: bytes 5..7 are pad/res/len8_dlc, not FD flags
    out.frame.res0 = 0;
    out.frame.res1 = 0;
  } else if (n == static_cast<ssize_t>(CANFD_MTU)) {
    out.frame.flags |= CANFD_FDF;
  } else {
    errno_ = EPROTO;
    return RecvResult::error;
  }
  // Kernel timestamps are CLOCK_REALTIME; convert to CLOCK_MONOTONIC with the current offset.
  out.timestamp_ns = rt::now_ns();
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec ts;
      std::memcpy(&ts, CMSG_DATA(c), sizeof(ts));
      const std::int64_t real = std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
      out.timestamp_ns += real - real_now_ns();
    }
  }
  return account_received(out.frame, state_, counters_);
}

void SocketCanBus::restart() noexcept {
  // RTM_NEWLINK with IFLA_LINKINFO/IFLA_INFO_DATA/IFLA_CAN_RESTART (what `ip link ... restart`
  // sends). Non-RT: call it from the driver's recovery path, not every cycle.
  const int nl = ::socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC, NETLINK_ROUTE);
  if (nl < 0) {
    errno_ = errno;
    return;
  }
  struct {
    nlmsghdr nh;
    ifinfomsg ifi;
    char attrs[64];
  } req{};
  req.nh.nlmsg_type = RTM_NEWLINK;
  req.nh.nlmsg_flags = NLM_F_REQUEST | NLM_F_ACK;
  req.ifi.ifi_family = AF_UNSPEC;
  req.ifi.ifi_index = ifindex_;
  auto* linkinfo = reinterpret_cast<rtattr*>(req.attrs);
  linkinfo->rta_type = IFLA_LINKINFO;
  auto* kind = reinterpret_cast<rtattr*>(reinterpret_cast<char*>(linkinfo) + RTA_LENGTH(0));
  kind->rta_type = IFLA_INFO_KIND;
  kind->rta_len = RTA_LENGTH(4);
  std::memcpy(RTA_DATA(kind), "can", 4);
  auto* data = reinterpret_cast<rtattr*>(reinterpret_cast<char*>(kind) + RTA_ALIGN(kind->rta_len));
  data->rta_type = IFLA_INFO_DATA;
  auto* restart = reinterpret_cast<rtattr*>(reinterpret_cast<char*>(data) + RTA_LENGTH(0));
  restart->rta_type = IFLA_CAN_RESTART;
  restart->rta_len = RTA_LENGTH(4);
  const std::uint32_t one = 1;
  std::memcpy(RTA_DATA(restart), &one, 4);
  data->rta_len = static_cast<unsigned short>(RTA_LENGTH(0) + RTA_ALIGN(restart->rta_len));
  linkinfo->rta_len = static_cast<unsigned short>(RTA_LENGTH(0) + RTA_ALIGN(kind->rta_len) + data->rta_len);
  req.nh.nlmsg_len = static_cast<std::uint32_t>(NLMSG_LENGTH(sizeof(ifinfomsg)) + RTA_ALIGN(linkinfo->rta_len));
  if (::send(nl, &req, req.nh.nlmsg_len, 0) < 0) {
    errno_ = errno;
  } else {
    state_ = BusState::error_active;  // the kernel confirms with CAN_ERR_RESTARTED
  }
  ::close(nl);
}

}  // namespace crease::drivers
