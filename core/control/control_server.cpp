#include "core/control/control_server.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdio>
#include <deque>
#include <set>
#include <thread>

#include <boost/asio.hpp>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/control/protocol.h"
#include "core/control/request_parser.h"
#include "core/control/socket_file.h"
#include "rt/thread_placement.h"

namespace crease::control {

namespace asio = boost::asio;
using Local = asio::local::stream_protocol;

namespace {

struct AtomicCounters {
  std::atomic<std::uint64_t> connections_accepted{0}, clients_active{0},
      rejected_too_many_clients{0}, rejected_peer_credentials{0}, requests{0}, replies_ok{0},
      malformed{0}, unknown_command{0}, bad_argument{0}, failed{0}, internal_errors{0},
      line_too_long{0}, partial_line_timeouts{0}, idle_timeouts{0}, idle_evictions{0},
      slow_reader_disconnects{0}, busy{0}, bytes_in{0}, bytes_out{0};
};

void bump(std::atomic<std::uint64_t>& c, std::uint64_t n = 1) {
  c.fetch_add(n, std::memory_order_relaxed);
}

// Best effort, never blocks: used for clients refused at accept time.
void send_and_close(Local::socket& s, const std::string& line) {
  (void)::send(s.native_handle(), line.data(), line.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
  boost::system::error_code ec;
  s.shutdown(Local::socket::shutdown_both, ec);
  s.close(ec);
}

}  // namespace

struct Session;

struct ControlServer::Impl {
  ServerOptions opt;
  RequestHandler& handler;
  asio::io_context io;       // accept, read, write, timers
  asio::io_context work;     // handler calls
  asio::executor_work_guard<asio::io_context::executor_type> work_guard{work.get_executor()};
  Local::acceptor acceptor{io};
  asio::steady_timer accept_retry{io};  // backs off after accept errors (e.g. EMFILE)
  std::optional<gid_t> group_gid;
  std::set<std::shared_ptr<Session>> sessions;  // I/O thread only
  AtomicCounters c;
  std::thread io_thread, work_thread;
  bool started = false;
  bool stopped = false;

  Impl(ServerOptions o, RequestHandler& h) : opt(std::move(o)), handler(h) {}
  void do_accept();
  bool peer_allowed(Local::socket& s) const;
  // Closes the session idle the longest to make room; false when none is idle.
  bool evict_oldest_idle();
};

struct Session : std::enable_shared_from_this<Session> {
  ControlServer::Impl& srv;
  Local::socket sock;
  asio::steady_timer timer;
  std::array<char, 4096> chunk{};
  std::string inbuf;
  std::deque<std::string> pending;   // complete lines not yet dispatched
  std::deque<std::string> outq;
  std::size_t out_bytes = 0;
  std::uint64_t timer_gen = 0;
  bool reading = false, writing = false, busy = false, closing = false, closed = false;
  std::chrono::steady_clock::time_point last_active = std::chrono::steady_clock::now();
  // Token bucket of the request rate: opt.max_requests_per_s tokens a second, as many at most.
  double tokens = 0;
  std::chrono::steady_clock::time_point refilled = last_active;

  Session(ControlServer::Impl& s, Local::socket&& so)
      : srv(s), sock(std::move(so)), timer(s.io), tokens(std::max(s.opt.max_requests_per_s, 1.0)) {}

  void start() { pump(); }

  // Waiting for a request with nothing half-read, queued, in the handler or unsent.
  [[nodiscard]] bool idle() const {
    return reading && !closing && !closed && !busy && inbuf.empty() && pending.empty() && outq.empty();
  }

  // Takes one token; false when the client is over its rate (0 = no limit).
  bool take_token() {
    const double rate = srv.opt.max_requests_per_s;
    if (rate <= 0) return true;
    const auto now = std::chrono::steady_clock::now();
    tokens = std::min(std::max(rate, 1.0), tokens + rate * std::chrono::duration<double>(now - refilled).count());
    refilled = now;
    if (tokens < 1.0) return false;
    tokens -= 1.0;
    return true;
  }

  void arm_timer() {
    const bool partial = !inbuf.empty();
    const auto timeout = partial ? srv.opt.partial_line_timeout : srv.opt.idle_timeout;
    const std::uint64_t gen = ++timer_gen;
    if (timeout.count() <= 0) return;
    timer.expires_after(timeout);
    timer.async_wait([self = shared_from_this(), gen, partial](boost::system::error_code ec) {
      if (ec || gen != self->timer_gen || self->closed || !self->reading) return;
      if (partial) {
        bump(self->srv.c.partial_line_timeouts);
        self->fail_and_close(kErrorTimeout, "incomplete request line timed out");
      } else {
        bump(self->srv.c.idle_timeouts);
        self->close();
      }
    });
  }

  void start_read() {
    reading = true;
    arm_timer();
    sock.async_read_some(asio::buffer(chunk), [self = shared_from_this()](
                                                  boost::system::error_code ec, std::size_t n) {
      self->reading = false;
      ++self->timer_gen;  // disarm
      if (self->closed) return;
      if (ec) {
        self->close();
        return;
      }
      bump(self->srv.c.bytes_in, n);
      self->last_active = std::chrono::steady_clock::now();
      self->on_data(n);
    });
  }

  void on_data(std::size_t n) {
    std::size_t scan_from = inbuf.size();
    inbuf.append(chunk.data(), n);
    std::size_t start = 0;
    for (std::size_t nl = inbuf.find('\n', scan_from); nl != std::string::npos;
         nl = inbuf.find('\n', start)) {
      std::string line = inbuf.substr(start, nl - start);
      start = nl + 1;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.size() > srv.opt.max_line_bytes) return oversize();
      if (!line.empty()) pending.push_back(std::move(line));
    }
    inbuf.erase(0, start);
    if (inbuf.size() > srv.opt.max_line_bytes) return oversize();
    pump();
  }

  void oversize() {
    bump(srv.c.line_too_long);
    inbuf.clear();
    pending.clear();
    fail_and_close(kErrorLineTooLong, "request line longer than " +
                                          std::to_string(srv.opt.max_line_bytes) + " bytes");
  }

  // Dispatches pending lines one at a time; reads more once all are answered.
  void pump() {
    while (!closing && !busy && !pending.empty()) {
      const std::string line = std::move(pending.front());
      pending.pop_front();
      bump(srv.c.requests);
      ParsedRequest parsed = parse_request(line);
      if (!take_token()) {
        bump(srv.c.busy);
        char why[96];
        std::snprintf(why, sizeof(why), "over this client's limit of %g requests per second; not handled",
                      srv.opt.max_requests_per_s);
        send(make_error(parsed.id, kErrorBusy, why));
        continue;
      }
      if (!parsed.ok()) {
        bump(parsed.error_code == kErrorMalformed     ? srv.c.malformed
             : parsed.error_code == kErrorBadArgument ? srv.c.bad_argument
                                                      : srv.c.unknown_command);
        send(make_error(parsed.id, parsed.error_code, parsed.error_message));
        continue;
      }
      busy = true;
      asio::post(srv.work, [self = shared_from_this(), req = std::move(parsed.request), id = parsed.id]() {
        nlohmann::json reply = self->call_handler(req, id);
        asio::post(self->srv.io, [self, reply = std::move(reply)]() {
          self->busy = false;
          self->send(reply);
          self->pump();
        });
      });
    }
    if (!closing && !busy && pending.empty() && !reading && !closed) start_read();
  }

  // Handler thread.
  nlohmann::json call_handler(const nlohmann::json& req, const nlohmann::json& id) {
    try {
      nlohmann::json result = srv.handler.handle(req);
      bump(srv.c.replies_ok);
      return make_ok(id, std::move(result));
    } catch (const RequestError& e) {
      bump(e.code() == kErrorBadArgument ? srv.c.bad_argument : srv.c.failed);
      return make_error(id, e.code(), e.message());
    } catch (const std::exception& e) {
      bump(srv.c.internal_errors);
      return make_error(id, kErrorInternal, e.what());
    } catch (...) {
      bump(srv.c.internal_errors);
      return make_error(id, kErrorInternal, "unknown exception");
    }
  }

  void send(const nlohmann::json& reply) {
    if (closed) return;
    std::string line = to_line(reply);
    if (out_bytes + line.size() > srv.opt.max_output_bytes) {
      bump(srv.c.slow_reader_disconnects);
      close();
      return;
    }
    out_bytes += line.size();
    outq.push_back(std::move(line));
    if (!writing) do_write();
  }

  void do_write() {
    writing = true;
    asio::async_write(sock, asio::buffer(outq.front()),
                      [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
                        self->writing = false;
                        if (self->closed) return;
                        if (ec) {
                          self->close();
                          return;
                        }
                        bump(self->srv.c.bytes_out, n);
                        self->last_active = std::chrono::steady_clock::now();
                        self->out_bytes -= self->outq.front().size();
                        self->outq.pop_front();
                        if (!self->outq.empty()) {
                          self->do_write();
                        } else if (self->closing) {
                          self->close();
                        }
                      });
  }

  // Sends an error, then disconnects once it is written (or after a grace period).
  void fail_and_close(const char* code, const std::string& message) {
    send(make_error(nullptr, code, message));
    begin_closing();
  }

  void begin_closing() {
    if (closed) return;
    closing = true;
    if (!writing && outq.empty()) {
      close();
      return;
    }
    const std::uint64_t gen = ++timer_gen;
    timer.expires_after(std::chrono::milliseconds(500));
    timer.async_wait([self = shared_from_this(), gen](boost::system::error_code ec) {
      if (!ec && gen == self->timer_gen) self->close();
    });
  }

  void close() {
    if (closed) return;
    closed = true;
    ++timer_gen;
    boost::system::error_code ec;
    timer.cancel();
    sock.shutdown(Local::socket::shutdown_both, ec);
    sock.close(ec);
    srv.c.clients_active.fetch_sub(1, std::memory_order_relaxed);
    srv.sessions.erase(shared_from_this());
  }
};

bool ControlServer::Impl::peer_allowed(Local::socket& s) const {
  ucred cred{};
  socklen_t len = sizeof(cred);
  if (::getsockopt(s.native_handle(), SOL_SOCKET, SO_PEERCRED, &cred, &len) != 0) return false;
  if (cred.uid == 0 || cred.uid == ::geteuid()) return true;
  for (uid_t u : opt.extra_allowed_uids) {
    if (cred.uid == u) return true;
  }
  return group_gid.has_value() && cred.gid == *group_gid;
}

bool ControlServer::Impl::evict_oldest_idle() {
  std::shared_ptr<Session> oldest;
  for (const auto& s : sessions) {
    if (s->idle() && (!oldest || s->last_active < oldest->last_active)) oldest = s;
  }
  if (!oldest) return false;
  bump(c.idle_evictions);
  oldest->close();
  return true;
}

void ControlServer::Impl::do_accept() {
  acceptor.async_accept([this](boost::system::error_code ec, Local::socket s) {
    if (ec == asio::error::operation_aborted || !acceptor.is_open()) return;
    if (ec) {
      // Out of descriptors or similar: retry later instead of spinning.
      accept_retry.expires_after(std::chrono::milliseconds(100));
      accept_retry.async_wait([this](boost::system::error_code wait_ec) {
        if (!wait_ec && acceptor.is_open()) do_accept();
      });
      return;
    }
    {
      if (!peer_allowed(s)) {
        bump(c.rejected_peer_credentials);
        send_and_close(s, to_line(make_error(nullptr, kErrorPermissionDenied,
                                             "peer uid is not allowed on this socket")));
      } else if (sessions.size() >= opt.max_clients && !evict_oldest_idle()) {
        bump(c.rejected_too_many_clients);
        send_and_close(s, to_line(make_error(nullptr, kErrorTooManyClients,
                                             "too many clients (" +
                                                 std::to_string(opt.max_clients) + ")")));
      } else {
        bump(c.connections_accepted);
        bump(c.clients_active);
        auto session = std::make_shared<Session>(*this, std::move(s));
        sessions.insert(session);
        session->start();
      }
    }
    do_accept();
  });
}

ControlServer::ControlServer(ServerOptions options, RequestHandler& handler)
    : impl_(std::make_unique<Impl>(std::move(options), handler)) {
  const std::string& path = impl_->opt.socket_path;
  if (path.empty()) throw ControlError("control socket: empty path");
  if (path.size() >= sizeof(sockaddr_un{}.sun_path)) {
    throw ControlError("control socket " + path + ": path too long");
  }
  ensure_parent_dir(path);
  remove_stale_socket(path);
  boost::system::error_code ec;
  impl_->acceptor.open(Local(), ec);
  if (!ec) {
    const mode_t old = ::umask(0177);  // the file is never accessible to others, even briefly
    impl_->acceptor.bind(Local::endpoint(path), ec);
    ::umask(old);
  }
  if (!ec) impl_->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) throw ControlError("control socket " + path + ": " + ec.message());
  try {
    impl_->group_gid = set_socket_permissions(path, impl_->opt.socket_group);
  } catch (...) {
    ::unlink(path.c_str());
    throw;
  }
}

ControlServer::~ControlServer() { stop(); }

void ControlServer::start() {
  Impl& m = *impl_;
  if (m.started) return;
  m.started = true;
  m.do_accept();
  m.work_thread = std::thread([&m] {
    rt::place_this_thread_non_rt("crease-ctl-work");
    m.work.run();
  });
  m.io_thread = std::thread([&m] {
    rt::place_this_thread_non_rt("crease-ctl-io");
    m.io.run();
  });
}

void ControlServer::stop() {
  Impl& m = *impl_;
  if (m.stopped) return;
  m.stopped = true;
  if (m.started) {
    asio::post(m.io, [&m] {
      boost::system::error_code ec;
      m.acceptor.close(ec);
      m.accept_retry.cancel();
      const auto snapshot = m.sessions;
      for (const auto& s : snapshot) s->begin_closing();
    });
    const auto deadline = std::chrono::steady_clock::now() + m.opt.stop_flush_timeout;
    while (m.c.clients_active.load() > 0 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    m.work_guard.reset();
    m.work.stop();
    m.io.stop();
    m.work_thread.join();
    m.io_thread.join();
  }
  for (const auto& s : m.sessions) {
    boost::system::error_code ec;
    s->sock.close(ec);
  }
  m.sessions.clear();
  boost::system::error_code ec;
  m.acceptor.close(ec);
  ::unlink(m.opt.socket_path.c_str());
}

ServerCounters ControlServer::counters() const {
  const AtomicCounters& a = impl_->c;
  ServerCounters s;
  s.connections_accepted = a.connections_accepted.load();
  s.clients_active = a.clients_active.load();
  s.rejected_too_many_clients = a.rejected_too_many_clients.load();
  s.rejected_peer_credentials = a.rejected_peer_credentials.load();
  s.requests = a.requests.load();
  s.replies_ok = a.replies_ok.load();
  s.malformed = a.malformed.load();
  s.unknown_command = a.unknown_command.load();
  s.bad_argument = a.bad_argument.load();
  s.failed = a.failed.load();
  s.internal_errors = a.internal_errors.load();
  s.line_too_long = a.line_too_long.load();
  s.partial_line_timeouts = a.partial_line_timeouts.load();
  s.idle_timeouts = a.idle_timeouts.load();
  s.idle_evictions = a.idle_evictions.load();
  s.slow_reader_disconnects = a.slow_reader_disconnects.load();
  s.busy = a.busy.load();
  s.bytes_in = a.bytes_in.load();
  s.bytes_out = a.bytes_out.load();
  return s;
}

const std::string& ControlServer::socket_path() const { return impl_->opt.socket_path; }

nlohmann::json ServerCounters::to_json() const {
  return nlohmann::json{{"connections_accepted", connections_accepted},
                        {"clients_active", clients_active},
                        {"rejected_too_many_clients", rejected_too_many_clients},
                        {"rejected_peer_credentials", rejected_peer_credentials},
                        {"requests", requests},
                        {"replies_ok", replies_ok},
                        {"malformed", malformed},
                        {"unknown_command", unknown_command},
                        {"bad_argument", bad_argument},
                        {"failed", failed},
                        {"internal_errors", internal_errors},
                        {"line_too_long", line_too_long},
                        {"partial_line_timeouts", partial_line_timeouts},
                        {"idle_timeouts", idle_timeouts},
                        {"idle_evictions", idle_evictions},
                        {"slow_reader_disconnects", slow_reader_disconnects},
                        {"busy", busy},
                        {"bytes_in", bytes_in},
                        {"bytes_out", bytes_out}};
}

}  // namespace crease::control
