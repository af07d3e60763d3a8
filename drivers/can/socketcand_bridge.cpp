#include "drivers/can/socketcand_bridge.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "drivers/can/socketcand_protocol.h"
#include "rt/clock.h"

namespace crease::drivers {
namespace {
struct Client {
  int fd;
  socketcand::StreamSplitter splitter;
  std::string out;       // pending bytes to the client
  bool opened = false;
  bool raw = false;
  std::int64_t raw_since_ns = 0;
};

// python-can 4.1 reads the "< ok >" answer to rawmode with a single recv() and compares it
// exactly, so frames must not share that TCP segment: forward frames only this long after it.
constexpr std::int64_t kRawmodeGraceNs = 50'000'000;
}  // namespace

SocketcandBridge::SocketcandBridge(CanBus& bus, std::uint16_t port, std::string interface)
    : bus_(bus), interface_(std::move(interface)) {
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  const int one = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 || ::listen(listen_fd_, 8) != 0) {
    const int e = errno;
    ::close(listen_fd_);
    throw std::runtime_error("socketcand bridge: cannot listen on 127.0.0.1:" + std::to_string(port) + ": " +
                             std::strerror(e));
  }
  socklen_t len = sizeof(a);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len);
  port_ = ntohs(a.sin_port);
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  thread_ = std::thread([this] { run(); });
}

SocketcandBridge::~SocketcandBridge() {
  stop_.store(true);
  const std::uint64_t v = 1;
  (void)!::write(wake_fd_, &v, sizeof(v));
  thread_.join();
  ::close(listen_fd_);
  ::close(wake_fd_);
}

SocketcandBridgeStats SocketcandBridge::stats() const noexcept {
  return {to_clients_.load(), from_clients_.load(), skipped_fd_.load(), bad_.load(), nobufs_.load()};
}

void SocketcandBridge::run() {
  std::vector<Client> clients;
  std::vector<pollfd> pfds;
  std::vector<CanFrame> pending_tx;  // client frames the bus refused for now (ENOBUFS)
  auto queue_text = [](Client& c, const char* s) { c.out += s; };
  while (!stop_.load()) {
    pfds.clear();
    pfds.push_back({wake_fd_, POLLIN, 0});
    pfds.push_back({listen_fd_, POLLIN, 0});
    pfds.push_back({bus_.fd(), POLLIN, 0});
    for (auto& c : clients) pfds.push_back({c.fd, static_cast<short>(POLLIN | (c.out.empty() ? 0 : POLLOUT)), 0});
    const int timeout_ms = pending_tx.empty() ? 10 : 1;
    if (::poll(pfds.data(), pfds.size(), timeout_ms) < 0 && errno != EINTR) break;
    if (pfds[1].revents & POLLIN) {
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd >= 0) {
        const int one = 1;
        ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
        clients.push_back(Client{fd, {}, {}, false, false, 0});
        queue_text(clients.back(), "< hi >");
      }
    }
    const std::int64_t now = rt::now_ns();
    // Bus -> clients.
    RxFrame rx;
    for (int i = 0; i < 512; ++i) {
      const RecvResult r = bus_.try_receive(rx);
      if (r == RecvResult::empty || r == RecvResult::error) break;
      if (r != RecvResult::frame) continue;
      char line[96];
      const std::size_t n = socketcand::format_frame(rx.frame, rx.timestamp_ns, line, sizeof(line));
      if (n == 0) {
        ++skipped_fd_;
        continue;
      }
      for (auto& c : clients) {
        if (c.raw && now - c.raw_since_ns >= kRawmodeGraceNs) {
          c.out.append(line, n);
          ++to_clients_;
        }
      }
    }
    // Clients -> bus, replies, output.
    for (std::size_t k = 0; k < clients.size();) {
      Client& c = clients[k];
      const short re = pfds[3 + k].revents;
      bool closed = false;
      if (re & (POLLIN | POLLHUP | POLLERR)) {
        char buf[4096];
        const ssize_t got = ::recv(c.fd, buf, sizeof(buf), 0);
        if (got == 0 || (got < 0 && errno != EAGAIN && errno != EINTR)) closed = true;
        for (std::size_t off = 0; got > 0 && off < static_cast<std::size_t>(got);) {
          const char* msg;
          std::size_t len;
          off += c.splitter.feed(buf + off, static_cast<std::size_t>(got) - off, &msg, &len);
          if (!msg) continue;
          socketcand::Message m;
          if (!socketcand::parse_message({msg, len}, m)) {
            ++bad_;
            queue_text(c, "< error parse >");
            continue;
          }
          switch (m.command) {
            case socketcand::Command::open:
              if (interface_ == m.interface) {
                c.opened = true;
                queue_text(c, "< ok >");
              } else {
                queue_text(c, "< error no such interface >");
              }
              break;
            case socketcand::Command::rawmode:
              if (c.opened) {
                c.raw = true;
                c.raw_since_ns = now;
                queue_text(c, "< ok >");
              } else {
                queue_text(c, "< error open first >");
              }
              break;
            case socketcand::Command::echo: queue_text(c, "< echo >"); break;
            case socketcand::Command::send:
              if (c.raw) {
                ++from_clients_;
                // As on a socketcand server (one raw socket per client, loopback on): every
                // other client of the bus sees the frame, the sender does not.
                char line[96];
                const std::size_t n = socketcand::format_frame(m.frame, now, line, sizeof(line));
                for (std::size_t j = 0; j < clients.size() && n > 0; ++j) {
                  Client& o = clients[j];
                  if (j != k && o.raw && now - o.raw_since_ns >= kRawmodeGraceNs) {
                    o.out.append(line, n);
                    ++to_clients_;
                  }
                }
                if (!pending_tx.empty() || bus_.send(m.frame) == SendResult::no_buffers) {
                  pending_tx.push_back(m.frame);
                  ++nobufs_;
                }
              }
              break;
            case socketcand::Command::unknown:
              ++bad_;
              queue_text(c, "< error unknown command >");
              break;
          }
        }
      }
      if (!closed && !c.out.empty()) {
        const ssize_t w = ::send(c.fd, c.out.data(), c.out.size(), MSG_NOSIGNAL);
        if (w > 0) c.out.erase(0, static_cast<std::size_t>(w));
        if (w < 0 && errno != EAGAIN && errno != EINTR) closed = true;
      }
      if (closed) {
        ::close(c.fd);
        clients.erase(clients.begin() + static_cast<std::ptrdiff_t>(k));
        pfds.erase(pfds.begin() + 3 + static_cast<std::ptrdiff_t>(k));
      } else {
        ++k;
      }
    }
    // Back-pressure: retry refused frames in order.
    std::size_t sent = 0;
    while (sent < pending_tx.size() && bus_.send(pending_tx[sent]) == SendResult::ok) ++sent;
    pending_tx.erase(pending_tx.begin(), pending_tx.begin() + static_cast<std::ptrdiff_t>(sent));
  }
  for (auto& c : clients) ::close(c.fd);
}

}  // namespace crease::drivers
