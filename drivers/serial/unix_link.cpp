#include "drivers/serial/unix_link.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace crease::drivers {
namespace {

sockaddr_un address_of(const std::string& path) {
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof(a.sun_path)) {
    throw std::runtime_error("the link path '" + path + "' is empty or longer than " +
                             std::to_string(sizeof(a.sun_path) - 1) + " characters");
  }
  std::memcpy(a.sun_path, path.c_str(), path.size() + 1);
  return a;
}

[[noreturn]] void fail(const std::string& path, const char* what) {
  throw std::runtime_error("link '" + path + "': " + what + ": " + std::strerror(errno));
}

// Whether a listener answers at PATH.
bool live(const std::string& path) {
  const sockaddr_un a = address_of(path);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  const bool ok = ::connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return ok;
}

}  // namespace

bool is_unix_socket(const std::string& path) noexcept {
  struct stat st{};
  return ::stat(path.c_str(), &st) == 0 && S_ISSOCK(st.st_mode);
}

int connect_unix_link(const std::string& path) {
  const sockaddr_un a = address_of(path);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) fail(path, "socket");
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    const int e = errno;
    ::close(fd);
    errno = e;
    fail(path, "connect");
  }
  if (::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK) != 0) {
    const int e = errno;
    ::close(fd);
    errno = e;
    fail(path, "O_NONBLOCK");
  }
  return fd;
}

UnixLinkListener::UnixLinkListener(const std::string& path) : path_(path) {
  const sockaddr_un a = address_of(path);
  struct stat st{};
  if (::lstat(path.c_str(), &st) == 0) {
    struct stat target{};
    const bool symlink_alive = S_ISLNK(st.st_mode) && ::stat(path.c_str(), &target) == 0 && !S_ISSOCK(target.st_mode);
    if (symlink_alive || live(path)) throw std::runtime_error("the link " + path + " is taken (another robot serves it)");
    ::unlink(path.c_str());  // what a dead robot left
  }
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) fail(path, "socket");
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0 || ::listen(fd_, 4) != 0) {
    const int e = errno;
    ::close(fd_);
    errno = e;
    fail(path, "bind/listen");
  }
}

UnixLinkListener::~UnixLinkListener() {
  ::close(fd_);
  ::unlink(path_.c_str());
}

int UnixLinkListener::accept_rt() noexcept { return ::accept4(fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC); }

bool unix_link_hung_up(int fd) noexcept {
  pollfd p{fd, POLLRDHUP, 0};
  return ::poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL)) != 0;
}

}  // namespace crease::drivers
