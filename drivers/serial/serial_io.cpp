#include "drivers/serial/serial_io.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace crease::drivers {

FdSerialIo::FdSerialIo(int fd) : fd_(fd), wake_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
  if (wake_fd_ < 0) throw std::runtime_error(std::string("eventfd: ") + std::strerror(errno));
  struct stat st{};
  socket_ = ::fstat(fd, &st) == 0 && S_ISSOCK(st.st_mode);
}

FdSerialIo::~FdSerialIo() { ::close(wake_fd_); }

long FdSerialIo::read_wait(std::span<std::uint8_t> buf, int timeout_ms) {
  pollfd p[2] = {{fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
  const int r = ::poll(p, 2, timeout_ms);
  if (r < 0) return errno == EINTR ? 0 : -errno;
  if (p[1].revents & POLLIN) {
    std::uint64_t v = 0;
    (void)!::read(wake_fd_, &v, sizeof v);
    return 0;
  }
  bool hung_up = (p[0].revents & POLLIN) == 0 && (p[0].revents & (POLLHUP | POLLERR | POLLNVAL)) != 0;
  if (p[0].revents & POLLIN) {
    const ssize_t n = ::read(fd_, buf.data(), buf.size());
    if (n > 0 || (n == 0 && !socket_)) return n;
    if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : -errno;
    hung_up = true;  // a socket's end of file: its peer closed
  }
  if (hung_up) {
    // A hung-up pty (no master yet, or gone) reports POLLHUP at once, a closed socket's peer
    // an end of file: wait out the timeout on the wake fd alone, so that the caller does not
    // spin.
    pollfd w{wake_fd_, POLLIN, 0};
    if (::poll(&w, 1, timeout_ms) > 0) {
      std::uint64_t v = 0;
      (void)!::read(wake_fd_, &v, sizeof v);
    }
    return -EIO;
  }
  return 0;
}

long FdSerialIo::write(std::span<const std::uint8_t> bytes) {
  const ssize_t n = socket_ ? ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT)
                           : ::write(fd_, bytes.data(), bytes.size());
  if (n >= 0) return n;
  return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : -errno;
}

void FdSerialIo::wake() noexcept {
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);
}

}  // namespace crease::drivers
