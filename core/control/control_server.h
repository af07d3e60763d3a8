// The control server: newline-delimited JSON on a Unix domain socket (Boost.Asio), never TCP.
//
//   struct Daemon : crease::control::RequestHandler {
//     nlohmann::json handle(const nlohmann::json& request) override;   // returns "result"
//   };
//   crease::control::ServerOptions opts;  opts.socket_path = crease::control::default_socket_path();
//   crease::control::ControlServer server(opts, daemon);   // binds now; throws ControlError
//   server.start();                                        // I/O + handler threads
//   ...
//   server.stop();                                         // flushes replies, unlinks the socket
//
// Threads: one I/O thread (accept, read, write, timers) and one handler thread that calls
// RequestHandler::handle serially, one request at a time, never on an RT thread. A slow
// handler delays replies but never reading, writing, or refusing other clients.
// The handler throws RequestError(code, message) for a failed command; any other exception
// becomes an "internal" error. Requests whose "cmd" is not in known_commands() are answered
// "unknown_command" without calling the handler.
//
// Requests are checked by parse_request (request_parser.h) before any handler sees them.
// Misbehaving clients get an error reply and/or a disconnect, and are counted (counters()):
// malformed JSON or a key twice (reply, stay connected), unknown commands (reply), bad
// arguments (reply), requests over max_requests_per_s (a `busy` reply, not handled), a line
// longer than max_line_bytes (reply, disconnect), a half-sent line older than
// partial_line_timeout (reply, disconnect), a client silent for idle_timeout (disconnect), a
// reader whose queued replies exceed max_output_bytes (disconnect), a peer whose SO_PEERCRED
// uid is not allowed (reply, disconnect). A new client finding max_clients connected takes
// the place of the one idle the longest (closed, counted); only when none is idle (each is
// mid-request) is it refused (reply, disconnect): silent clients keep no one out.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <sys/types.h>

namespace crease::control {

class ControlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Called on the server's handler thread only, one request at a time.
struct RequestHandler {
  virtual ~RequestHandler() = default;
  // REQUEST is an object whose "cmd" is a known command. Returns the reply's "result".
  // Throws RequestError for a failed request. Must not call ControlServer::stop().
  virtual nlohmann::json handle(const nlohmann::json& request) = 0;
};

struct ServerOptions {
  std::string socket_path;                 // parent folder created 0700 when missing
  std::optional<std::string> socket_group; // chown to this group, mode 0660 (else 0600)
  std::size_t max_line_bytes = 64 * 1024;  // request line limit, newline excluded
  std::size_t max_output_bytes = 1 << 20;  // queued reply bytes per client before disconnect
  std::size_t max_clients = 128;
  std::chrono::milliseconds partial_line_timeout{5000};  // half-sent line -> disconnect
  std::chrono::milliseconds idle_timeout{30000};         // silent client -> closed; 0 = never
  // Requests a second per client (a token bucket of as many, at least 1): beyond it each
  // request is answered `busy` unhandled. 0 = no limit.
  double max_requests_per_s = 500;
  std::chrono::milliseconds stop_flush_timeout{500};     // stop(): time to flush replies
  // Peers allowed besides this process's euid and root (e.g. for tests); the group's gid
  // is also allowed when socket_group is set.
  std::vector<uid_t> extra_allowed_uids;
};

// A snapshot of the server's counters (monotonic, except clients_active).
struct ServerCounters {
  std::uint64_t connections_accepted = 0;
  std::uint64_t clients_active = 0;
  std::uint64_t rejected_too_many_clients = 0;
  std::uint64_t rejected_peer_credentials = 0;
  std::uint64_t requests = 0;         // complete lines that reached dispatch
  std::uint64_t replies_ok = 0;
  std::uint64_t malformed = 0;        // not JSON, a key twice, not an object, no string "cmd"
  std::uint64_t unknown_command = 0;
  std::uint64_t bad_argument = 0;     // an argument outside the spec or mistyped; or the handler's
  std::uint64_t failed = 0;           // handler threw RequestError with another code
  std::uint64_t internal_errors = 0;  // handler threw something else
  std::uint64_t line_too_long = 0;
  std::uint64_t partial_line_timeouts = 0;
  std::uint64_t idle_timeouts = 0;
  std::uint64_t idle_evictions = 0;   // idle clients closed to let a new one in
  std::uint64_t slow_reader_disconnects = 0;
  std::uint64_t busy = 0;             // requests over the client's rate, answered `busy`
  std::uint64_t bytes_in = 0;
  std::uint64_t bytes_out = 0;

  [[nodiscard]] nlohmann::json to_json() const;
};

class ControlServer {
 public:
  // Creates the socket file (replacing a stale one nobody listens on) and listens.
  // @throws ControlError naming the path and the reason.
  ControlServer(ServerOptions options, RequestHandler& handler);
  ~ControlServer();  // stop()
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  // Starts the I/O and handler threads. Call once.
  void start();
  // Stops accepting, gives queued replies up to stop_flush_timeout, closes every client,
  // joins the threads and removes the socket file. Idempotent. Not from the handler.
  void stop();

  [[nodiscard]] ServerCounters counters() const;
  [[nodiscard]] const std::string& socket_path() const;

 private:
  friend struct Session;  // one client connection (control_server.cpp)
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crease::control
