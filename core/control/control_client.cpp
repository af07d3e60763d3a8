#include "core/control/control_client.h"

#include <cerrno>
#include <cstring>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

namespace crease::control {
namespace {

using Kind = ClientError::Kind;

std::chrono::steady_clock::time_point deadline_after(std::chrono::milliseconds t) {
  return std::chrono::steady_clock::now() + t;
}

// Waits for EVENTS on FD until DEADLINE. Returns false on timeout.
bool wait_fd(int fd, short events, std::chrono::steady_clock::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, events, 0};
    const int rc = ::poll(&p, 1, static_cast<int>(left.count()));
    if (rc > 0) return true;
    if (rc < 0 && errno != EINTR) return true;  // let the read/write report the error
  }
}

}  // namespace

ControlClient::ControlClient(const std::string& path, std::chrono::milliseconds timeout)
    : timeout_(timeout), path_(path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof(addr.sun_path)) throw ClientError(Kind::io, path + ": path too long");
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw ClientError(Kind::io, std::string("socket(): ") + std::strerror(errno));
  if (::connect(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
    const int err = errno;
    ::close(fd_);
    fd_ = -1;
    if (err == ENOENT || err == ECONNREFUSED) {
      throw ClientError(Kind::not_running,
                        "creased is not running (no listener on " + path + ")");
    }
    if (err == EACCES || err == EPERM) {
      throw ClientError(Kind::permission, "permission denied on " + path);
    }
    throw ClientError(Kind::io, "cannot connect to " + path + ": " + std::strerror(err));
  }
}

ControlClient::~ControlClient() {
  if (fd_ >= 0) ::close(fd_);
}

void ControlClient::send_raw(const std::string& bytes) {
  const auto deadline = deadline_after(timeout_);
  std::size_t off = 0;
  while (off < bytes.size()) {
    const ssize_t n =
        ::send(fd_, bytes.data() + off, bytes.size() - off, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      off += static_cast<std::size_t>(n);
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      if (!wait_fd(fd_, POLLOUT, deadline)) throw ClientError(Kind::timeout, "send timed out");
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      throw ClientError(Kind::io, "creased closed the connection (" +
                                      std::string(std::strerror(errno)) + ")");
    }
  }
}

std::optional<std::string> ControlClient::read_line() {
  const auto deadline = deadline_after(timeout_);
  for (;;) {
    const auto nl = inbuf_.find('\n');
    if (nl != std::string::npos) {
      std::string line = inbuf_.substr(0, nl);
      inbuf_.erase(0, nl + 1);
      return line;
    }
    if (!wait_fd(fd_, POLLIN, deadline)) throw ClientError(Kind::timeout, "no reply in time");
    char buf[8192];
    const ssize_t n = ::recv(fd_, buf, sizeof(buf), MSG_DONTWAIT);
    if (n > 0) {
      inbuf_.append(buf, static_cast<std::size_t>(n));
    } else if (n == 0 || (n < 0 && errno == ECONNRESET)) {
      return std::nullopt;
    } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      throw ClientError(Kind::io, std::string("read: ") + std::strerror(errno));
    }
  }
}

nlohmann::json ControlClient::request(nlohmann::json req) {
  if (!req.contains("id")) req["id"] = next_id_++;
  try {
    send_raw(req.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  } catch (const ClientError&) {
    // The server may have refused us and closed already: prefer its reply when there is one.
  }
  const std::optional<std::string> line = read_line();
  if (!line) throw ClientError(Kind::io, "creased closed the connection without replying");
  nlohmann::json reply = nlohmann::json::parse(*line, nullptr, false);
  if (reply.is_discarded() || !reply.is_object()) {
    throw ClientError(Kind::protocol, "reply is not a JSON object: " + line->substr(0, 200));
  }
  return reply;
}

}  // namespace crease::control
