// The control socket of the mock bus: addresses, and records with descriptors (mock_wire.h).
#include "drivers/can/mock_wire.h"

#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <stdexcept>

namespace crease::drivers {

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

ssize_t send_record(int sock, const Record& r, const int* fds, int nfds, int flags) noexcept {
  nfds = std::clamp(nfds, 0, kMaxFds);
  iovec iov{const_cast<Record*>(&r), sizeof(r)};
  alignas(cmsghdr) char ctl[CMSG_SPACE(kMaxFds * sizeof(int))] = {};
  msghdr mh{};
  mh.msg_iov = &iov;
  mh.msg_iovlen = 1;
  if (nfds > 0) {
    mh.msg_control = ctl;
    mh.msg_controllen = CMSG_SPACE(nfds * sizeof(int));
    cmsghdr* cm = CMSG_FIRSTHDR(&mh);
    cm->cmsg_level = SOL_SOCKET;
    cm->cmsg_type = SCM_RIGHTS;
    cm->cmsg_len = CMSG_LEN(nfds * sizeof(int));
    std::memcpy(CMSG_DATA(cm), fds, nfds * sizeof(int));
  }
  return ::sendmsg(sock, &mh, flags | MSG_NOSIGNAL);
}

ssize_t recv_record(int sock, Record& r, int (&fds)[kMaxFds], int flags) noexcept {
  for (int& fd : fds) fd = -1;
  iovec iov{&r, sizeof(r)};
  alignas(cmsghdr) char ctl[CMSG_SPACE(kMaxFds * sizeof(int))] = {};
  msghdr mh{};
  mh.msg_iov = &iov;
  mh.msg_iovlen = 1;
  mh.msg_control = ctl;
  mh.msg_controllen = sizeof(ctl);
  const ssize_t got = ::recvmsg(sock, &mh, flags | MSG_CMSG_CLOEXEC);
  if (got < 0) return got;
  int n = 0;
  for (cmsghdr* cm = CMSG_FIRSTHDR(&mh); cm; cm = CMSG_NXTHDR(&mh, cm)) {
    if (cm->cmsg_level != SOL_SOCKET || cm->cmsg_type != SCM_RIGHTS) continue;
    const std::size_t count = (cm->cmsg_len - CMSG_LEN(0)) / sizeof(int);
    for (std::size_t k = 0; k < count; ++k) {
      int fd;
      std::memcpy(&fd, CMSG_DATA(cm) + k * sizeof(int), sizeof(int));
      if (n < kMaxFds) {
        fds[n++] = fd;
      } else {
        ::close(fd);  // more than the protocol sends: not ours to keep
      }
    }
  }
  return got;
}
}  // namespace mockwire

}  // namespace crease::drivers
