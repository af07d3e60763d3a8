// Tests for core/control/control_server.h with a test handler: framing, dispatch, error
// replies and counters, limits (line size, partial lines, slow readers, client count), the
// socket file's mode and a peer with another uid.
#include "core/control/control_server.h"

#include <doctest/doctest.h>

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>
#include <vector>

#include "core/control/control_client.h"
#include "core/control/protocol.h"
#include "core/control/socket_path.h"

namespace ctl = crease::control;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

// Echoes its arguments; 'param' needs instance/key; 'stop' throws a plain exception;
// 'ports' returns BIG bytes of payload (slow-reader test); 'activate' fails with a NUL in its
// message; every 'stop' that reaches it is counted.
struct TestHandler : ctl::RequestHandler {
  std::atomic<int> calls{0};
  std::atomic<int> stops{0};
  std::size_t big = 4096;
  json handle(const json& request) override {
    ++calls;
    const std::string cmd = request.at("cmd");
    if (cmd == "activate") throw ctl::RequestError(ctl::kErrorFailed, std::string("before\0after", 12));
    if (cmd == "stop") ++stops;
    if (cmd == "status") return json{{"state", "running"}, {"echo", request}};
    if (cmd == "param") {
      return json{{"instance", ctl::require_string(request, "instance")},
                  {"key", ctl::require_string(request, "key")}};
    }
    if (cmd == "load") {
      (void)ctl::require_int(request, "order");
      throw ctl::RequestError(ctl::kErrorFailed, "library not found");
    }
    if (cmd == "ports") return json{{"blob", std::string(big, 'x')}};
    if (cmd == "stop") throw std::runtime_error("boom");
    return json::object();
  }
};

std::string test_dir() {
  static int n = 0;
  return "/tmp/crease_ctl_test_" + std::to_string(::getpid()) + "_" + std::to_string(n++);
}

ctl::ServerOptions options_in(const std::string& dir) {
  ctl::ServerOptions o;
  o.socket_path = dir + "/sub/creased.sock";
  return o;
}

template <typename Pred>
bool eventually(Pred pred, std::chrono::milliseconds limit = 3000ms) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(5ms);
  }
  return pred();
}

mode_t mode_of(const std::string& path) {
  struct stat st {};
  REQUIRE(::lstat(path.c_str(), &st) == 0);
  return st.st_mode;
}

}  // namespace

TEST_CASE("default socket path rule") {
  CHECK(ctl::default_socket_path(0, "/run/user/0") == "/run/crease/creased.sock");
  CHECK(ctl::default_socket_path(1000, "/run/user/1000") == "/run/user/1000/crease/creased.sock");
  CHECK(ctl::default_socket_path(1000, nullptr) == "/tmp/crease-1000/creased.sock");
  CHECK(ctl::default_socket_path(1000, "") == "/tmp/crease-1000/creased.sock");
  CHECK_FALSE(ctl::default_socket_path().empty());
}

TEST_CASE("socket file: 0600 in a 0700 folder; stale replaced, live and foreign files refused") {
  const std::string dir = test_dir();
  TestHandler h;
  const auto opt = options_in(dir);
  {
    ctl::ControlServer server(opt, h);
    server.start();
    CHECK(S_ISSOCK(mode_of(opt.socket_path)));
    CHECK((mode_of(opt.socket_path) & 0777) == 0600);
    CHECK((mode_of(dir + "/sub") & 0777) == 0700);
    // Someone listens: a second server must not steal the path.
    CHECK_THROWS_AS(ctl::ControlServer(opt, h), ctl::ControlError);
    ctl::ControlClient client(opt.socket_path);
    CHECK(client.request({{"cmd", "status"}})["ok"] == true);
  }
  CHECK_FALSE(std::filesystem::exists(opt.socket_path));  // stop() removed it
  {
    // A live socket is never stolen.
    ctl::ControlServer a(opt, h);
    a.start();
    CHECK_THROWS_WITH_AS(ctl::ControlServer(opt, h), doctest::Contains("already in use"),
                         ctl::ControlError);
  }
  {
    // A stale socket (bound, nobody listening) is replaced.
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::snprintf(addr.sun_path, sizeof(addr.sun_path), "%s", opt.socket_path.c_str());
    REQUIRE(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0);
    ::close(fd);
    REQUIRE(std::filesystem::exists(opt.socket_path));
    ctl::ControlServer b(opt, h);
    b.start();
    ctl::ControlClient client(opt.socket_path);
    CHECK(client.request({{"cmd", "status"}})["ok"] == true);
  }
  {
    std::FILE* f = std::fopen(opt.socket_path.c_str(), "w");
    REQUIRE(f != nullptr);
    std::fclose(f);
    CHECK_THROWS_WITH_AS(ctl::ControlServer(opt, h), doctest::Contains("not a socket"),
                         ctl::ControlError);
  }
  CHECK_THROWS_AS(ctl::ControlClient(dir + "/nothing.sock"), ctl::ClientError);
  try {
    ctl::ControlClient c(dir + "/nothing.sock");
  } catch (const ctl::ClientError& e) {
    CHECK(e.kind() == ctl::ClientError::Kind::not_running);
    CHECK(std::string(e.what()).find("not running") != std::string::npos);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("replies, error objects and counters for malformed and bad requests") {
  const std::string dir = test_dir();
  TestHandler h;
  ctl::ControlServer server(options_in(dir), h);
  server.start();
  ctl::ControlClient c(server.socket_path());

  json r = c.request({{"id", "abc"}, {"cmd", "status"}});
  CHECK(r["id"] == "abc");
  CHECK(r["ok"] == true);
  CHECK(r["result"]["state"] == "running");
  CHECK(r["result"]["echo"]["cmd"] == "status");

  c.send_raw("this is not json\n");
  r = json::parse(c.read_line().value());
  CHECK(r["ok"] == false);
  CHECK(r["id"].is_null());
  CHECK(r["error"]["code"] == ctl::kErrorMalformed);

  c.send_raw("[1,2,3]\n{\"id\":5}\n\r\n\n");  // not an object; no cmd; blank lines ignored
  CHECK(json::parse(c.read_line().value())["error"]["code"] == ctl::kErrorMalformed);
  r = json::parse(c.read_line().value());
  CHECK(r["id"] == 5);
  CHECK(r["error"]["code"] == ctl::kErrorMalformed);

  r = c.request({{"cmd", "dance"}});
  CHECK(r["error"]["code"] == ctl::kErrorUnknownCommand);
  CHECK(r["error"]["message"] == "unknown command 'dance'");

  r = c.request({{"cmd", "param"}, {"instance", "counter"}});
  CHECK(r["error"]["code"] == ctl::kErrorBadArgument);
  CHECK(r["error"]["message"] == "'param' needs the argument 'key'");
  r = c.request({{"cmd", "param"}, {"instance", 3}, {"key", "k"}});
  CHECK(r["error"]["code"] == ctl::kErrorBadArgument);
  r = c.request({{"cmd", "load"}, {"order", "ten"}});
  CHECK(r["error"]["code"] == ctl::kErrorBadArgument);
  r = c.request({{"cmd", "load"}, {"order", 10}});
  CHECK(r["error"]["code"] == ctl::kErrorFailed);
  CHECK(r["error"]["message"] == "library not found");
  r = c.request({{"cmd", "stop"}});
  CHECK(r["error"]["code"] == ctl::kErrorInternal);
  // Pipelined requests are answered in order.
  c.send_raw("{\"id\":1,\"cmd\":\"status\"}\n{\"id\":2,\"cmd\":\"status\"}\n");
  CHECK(json::parse(c.read_line().value())["id"] == 1);
  CHECK(json::parse(c.read_line().value())["id"] == 2);
  // Invalid UTF-8 in a string is replaced in the reply, not a crash.
  c.send_raw("{\"cmd\":\"status\",\"s\":\"\xff\"}\n");
  CHECK(json::parse(c.read_line().value())["ok"] == false);  // parse rejects invalid UTF-8

  const ctl::ServerCounters k = server.counters();
  CHECK(k.malformed == 4);
  CHECK(k.unknown_command == 1);
  CHECK(k.bad_argument == 3);
  CHECK(k.failed == 1);
  CHECK(k.internal_errors == 1);
  CHECK(k.replies_ok == 3);
  CHECK(k.requests == 13);
  CHECK(k.busy == 0);
  CHECK(k.clients_active == 1);
  CHECK(k.to_json()["malformed"] == 4);
  server.stop();
  std::filesystem::remove_all(dir);
}

TEST_CASE("strict requests: a key twice, a mistyped or unknown argument never reach the handler") {
  const std::string dir = test_dir();
  TestHandler h;
  ctl::ControlServer server(options_in(dir), h);
  server.start();
  ctl::ControlClient c(server.socket_path());
  // The last "cmd" would be stop: the request is malformed, nothing is stopped.
  c.send_raw("{\"id\":1,\"cmd\":\"status\",\"cmd\":\"stop\"}\n");
  json r = json::parse(c.read_line().value());
  CHECK(r["error"]["code"] == ctl::kErrorMalformed);
  CHECK(r["error"]["message"] == "request has the key 'cmd' twice");
  CHECK(h.stops == 0);
  CHECK(h.calls == 0);
  r = c.request({{"cmd", "load"}, {"instance", "a"}, {"library", "b"}, {"loop", "c"}, {"order", 1}, {"ports", {1}}});
  CHECK(r["error"]["code"] == ctl::kErrorBadArgument);
  CHECK(r["error"]["message"] == "'load': argument 'ports' must be an object of strings");
  r = c.request({{"cmd", "param"}, {"action", "set"}, {"instance", "c"}, {"key", "k"}, {"value", "0x10"}});
  CHECK(r["error"]["code"] == ctl::kErrorBadArgument);
  r = c.request({{"cmd", "status"}, {"extra", 7}});
  CHECK(r["error"]["message"] == "'status' takes no argument 'extra'");
  CHECK(h.calls == 0);
  // A handler's message with a NUL inside reaches the client whole.
  r = c.request({{"cmd", "activate"}, {"instance", "x"}});
  CHECK(r["error"]["code"] == ctl::kErrorFailed);
  CHECK(r["error"]["message"] == std::string("before\0after", 12));
  // The one stop that is well-formed does reach it.
  CHECK(c.request({{"cmd", "stop"}})["error"]["code"] == ctl::kErrorInternal);
  CHECK(h.stops == 1);
  CHECK(server.counters().malformed == 1);
  CHECK(server.counters().bad_argument == 3);
  server.stop();
  std::filesystem::remove_all(dir);
}

TEST_CASE("a line over the size limit gets an error, then a disconnect") {
  const std::string dir = test_dir();
  TestHandler h;
  ctl::ControlServer server(options_in(dir), h);
  server.start();
  ctl::ControlClient c(server.socket_path());
  const std::string huge(70 * 1024, 'a');  // no newline: the limit applies to buffered data
  try {
    c.send_raw(huge);
  } catch (const ctl::ClientError&) {
    // the server may close before everything is sent
  }
  const auto line = c.read_line();
  REQUIRE(line.has_value());
  CHECK(json::parse(*line)["error"]["code"] == ctl::kErrorLineTooLong);
  CHECK_FALSE(c.read_line().has_value());
  CHECK(server.counters().line_too_long == 1);

  // A complete line over the limit, too.
  ctl::ControlClient d(server.socket_path());
  try {
    d.send_raw("{\"cmd\":\"status\",\"pad\":\"" + std::string(65 * 1024, 'b') + "\"}\n");
  } catch (const ctl::ClientError&) {
  }
  CHECK(json::parse(d.read_line().value())["error"]["code"] == ctl::kErrorLineTooLong);
  CHECK(eventually([&] { return server.counters().line_too_long == 2; }));
  // Other clients are unaffected.
  ctl::ControlClient e(server.socket_path());
  CHECK(e.request({{"cmd", "status"}})["ok"] == true);
  std::filesystem::remove_all(dir);
}

TEST_CASE("a half-sent line times out with an error and a disconnect; idle clients too") {
  const std::string dir = test_dir();
  TestHandler h;
  auto opt = options_in(dir);
  opt.partial_line_timeout = 150ms;
  opt.idle_timeout = 400ms;
  ctl::ControlServer server(opt, h);
  server.start();
  ctl::ControlClient c(server.socket_path());
  c.send_raw("{\"cmd\": \"sta");
  const auto line = c.read_line();
  REQUIRE(line.has_value());
  CHECK(json::parse(*line)["error"]["code"] == ctl::kErrorTimeout);
  CHECK_FALSE(c.read_line().has_value());
  CHECK(server.counters().partial_line_timeouts == 1);

  ctl::ControlClient idle(server.socket_path());
  CHECK_FALSE(idle.read_line().has_value());  // closed without a reply
  CHECK(server.counters().idle_timeouts == 1);
  std::filesystem::remove_all(dir);
}

TEST_CASE("100 concurrent clients are all served; beyond max_clients, with none idle, refused") {
  const std::string dir = test_dir();
  TestHandler h;
  auto opt = options_in(dir);
  opt.max_clients = 100;
  ctl::ControlServer server(opt, h);
  server.start();
  std::vector<std::unique_ptr<ctl::ControlClient>> clients;
  for (int i = 0; i < 100; ++i) {
    clients.push_back(std::make_unique<ctl::ControlClient>(server.socket_path()));
  }
  for (int i = 0; i < 100; ++i) {
    clients[i]->send_raw("{\"id\":" + std::to_string(i) + ",\"cmd\":\"status\"}\n");
  }
  int ok = 0;
  for (int i = 0; i < 100; ++i) {
    const json r = json::parse(clients[i]->read_line().value());
    ok += (r["ok"] == true && r["id"] == i) ? 1 : 0;
  }
  CHECK(ok == 100);
  CHECK(server.counters().clients_active == 100);

  // Each one mid-request (half a line sent): none is idle, none yields its place.
  const std::uint64_t read_before = server.counters().bytes_in;
  for (int i = 0; i < 100; ++i) clients[i]->send_raw("{\"cmd\":");
  REQUIRE(eventually([&] { return server.counters().bytes_in == read_before + 100 * 7; }));
  ctl::ControlClient extra(server.socket_path());
  const auto line = extra.read_line();
  REQUIRE(line.has_value());
  CHECK(json::parse(*line)["error"]["code"] == ctl::kErrorTooManyClients);
  CHECK_FALSE(extra.read_line().has_value());
  CHECK(server.counters().rejected_too_many_clients == 1);

  // 100 threads at once, each with its own connection, after the first batch leaves.
  clients.clear();
  REQUIRE(eventually([&] { return server.counters().clients_active == 0; }));
  std::atomic<int> served{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < 100; ++i) {
    threads.emplace_back([&] {
      try {
        ctl::ControlClient c(server.socket_path());
        for (int k = 0; k < 5; ++k) {
          if (c.request({{"cmd", "status"}})["ok"] == true) ++served;
        }
      } catch (const ctl::ClientError&) {
      }
    });
  }
  for (auto& t : threads) t.join();
  CHECK(served == 500);
  std::filesystem::remove_all(dir);
}

TEST_CASE("130 silent clients keep no one out: the idlest yields to a new client, and all time out") {
  const std::string dir = test_dir();
  TestHandler h;
  auto opt = options_in(dir);
  REQUIRE(opt.max_clients == 128);
  REQUIRE(opt.idle_timeout == 30s);  // on by default
  opt.idle_timeout = 1500ms;
  ctl::ControlServer server(opt, h);
  server.start();
  std::vector<std::unique_ptr<ctl::ControlClient>> silent;
  for (int i = 0; i < 130; ++i) silent.push_back(std::make_unique<ctl::ControlClient>(server.socket_path()));
  REQUIRE(eventually([&] { return server.counters().connections_accepted == 130; }));
  CHECK(server.counters().rejected_too_many_clients == 0);
  CHECK(server.counters().idle_evictions == 2);  // the 129th and the 130th took the oldest places
  CHECK(server.counters().clients_active == 128);
  // A client that speaks now is served at once, while the silent ones are still there.
  {
    ctl::ControlClient c(server.socket_path());
    CHECK(c.request({{"cmd", "status"}})["ok"] == true);
  }
  CHECK(server.counters().idle_evictions == 3);
  // The first two were closed without a reply; the last one is still open.
  CHECK_FALSE(silent[0]->read_line().has_value());
  CHECK_FALSE(silent[1]->read_line().has_value());
  // Then the idle timeout closes every silent one.
  CHECK(eventually([&] { return server.counters().clients_active == 0; }, 20s));
  CHECK(server.counters().idle_timeouts >= 127);
  CHECK_FALSE(silent[129]->read_line().has_value());
  std::filesystem::remove_all(dir);
}

TEST_CASE("a client over its request rate is answered busy, counted; the others are not") {
  const std::string dir = test_dir();
  TestHandler h;
  auto opt = options_in(dir);
  CHECK(opt.max_requests_per_s == 500.0);  // the default
  opt.max_requests_per_s = 1;  // one a second: 40 pipelined requests would need 39 s to pass
  ctl::ControlServer server(opt, h);
  server.start();
  ctl::ControlClient fast(server.socket_path());
  std::string burst;
  for (int i = 0; i < 40; ++i) burst += "{\"id\":" + std::to_string(i) + ",\"cmd\":\"status\"}\n";
  fast.send_raw(burst);
  int ok = 0, busy = 0;
  for (int i = 0; i < 40; ++i) {
    const json r = json::parse(fast.read_line().value());
    CHECK(r["id"] == i);  // in order, each echoing its id
    if (r["ok"] == true) ++ok;
    if (!r["ok"].get<bool>() && r["error"]["code"] == ctl::kErrorBusy) ++busy;
  }
  CHECK(ok >= 1);
  CHECK(busy >= 20);
  CHECK(ok + busy == 40);
  CHECK(h.calls == ok);  // a busy request is never handled
  CHECK(server.counters().busy == static_cast<std::uint64_t>(busy));
  CHECK(server.counters().to_json()["busy"] == busy);
  // Another client has its own budget.
  ctl::ControlClient other(server.socket_path());
  CHECK(other.request({{"cmd", "status"}})["ok"] == true);
  std::filesystem::remove_all(dir);
}

TEST_CASE("a client that never reads is disconnected; others keep being served") {
  const std::string dir = test_dir();
  TestHandler h;
  h.big = 8192;
  auto opt = options_in(dir);
  opt.max_output_bytes = 64 * 1024;
  opt.max_requests_per_s = 0;  // the hog's requests are all handled: its replies pile up
  ctl::ControlServer server(opt, h);
  server.start();
  ctl::ControlClient hog(server.socket_path(), 2000ms);
  ctl::ControlClient polite(server.socket_path());
  bool disconnected = false;
  for (int i = 0; i < 2000 && !disconnected; ++i) {
    try {
      hog.send_raw("{\"cmd\":\"ports\"}\n");
    } catch (const ctl::ClientError&) {
      disconnected = true;
    }
    if (i % 20 == 0) {
      CHECK(polite.request({{"cmd", "status"}})["ok"] == true);
      disconnected = disconnected || server.counters().slow_reader_disconnects == 1;
    }
  }
  CHECK(disconnected);
  CHECK(eventually([&] { return server.counters().slow_reader_disconnects == 1; }));
  CHECK(polite.request({{"cmd", "status"}})["ok"] == true);
  std::filesystem::remove_all(dir);
}

TEST_CASE("a peer with another uid is refused") {
  if (::geteuid() != 0) {
    MESSAGE("SKIPPED: needs root to run a client as uid 65534");
    return;
  }
  const std::string dir = test_dir();
  TestHandler h;
  ctl::ControlServer server(options_in(dir), h);
  server.start();
  // Returns the child's exit status: 10 = refused at connect (file mode), 11 = refused by
  // SO_PEERCRED with a permission_denied reply, 1 = served (a failure), 2 = other.
  auto run_child = [&] {
    const pid_t pid = ::fork();
    if (pid == 0) {
      if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(3);
      try {
        ctl::ControlClient c(server.socket_path(), 2000ms);
        const json r = c.request({{"cmd", "status"}});
        if (r["ok"] == true) ::_exit(1);
        ::_exit(r["error"]["code"] == ctl::kErrorPermissionDenied ? 11 : 2);
      } catch (const ctl::ClientError& e) {
        ::_exit(e.kind() == ctl::ClientError::Kind::permission ? 10 : 2);
      }
      ::_exit(2);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  CHECK(run_child() == 10);  // 0600 socket in a 0700 folder: the kernel refuses
  // Loosen the file system permissions: SO_PEERCRED must still refuse.
  REQUIRE(::chmod((dir + "/sub").c_str(), 0755) == 0);
  REQUIRE(::chmod(dir.c_str(), 0755) == 0);
  REQUIRE(::chmod(server.socket_path().c_str(), 0666) == 0);
  CHECK(run_child() == 11);
  CHECK(server.counters().rejected_peer_credentials == 1);
  std::filesystem::remove_all(dir);
}

TEST_CASE("stop() while many clients are mid-request and the handler is busy") {
  struct SlowHandler : ctl::RequestHandler {
    json handle(const json& request) override {
      if (request["cmd"] == "swap") std::this_thread::sleep_for(20ms);
      return json{{"ok", true}};
    }
  } h;
  const std::string dir = test_dir();
  ctl::ControlServer server(options_in(dir), h);
  server.start();
  std::atomic<bool> done{false};
  std::atomic<int> replies{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < 20; ++i) {
    threads.emplace_back([&, i] {
      while (!done) {
        try {
          ctl::ControlClient c(server.socket_path(), 2000ms);
          for (int k = 0; k < 3 && !done; ++k) {
            if (c.request({{"cmd", (i + k) % 3 == 0 ? "swap" : "status"}})["ok"] == true) ++replies;
          }
          if (i % 2 == 0) c.send_raw("{\"cmd\":\"sta");  // leave half a line behind
        } catch (const ctl::ClientError&) {
          // expected once the server is gone
        }
      }
    });
  }
  REQUIRE(eventually([&] { return replies > 50; }));
  const auto t0 = std::chrono::steady_clock::now();
  server.stop();
  const auto took = std::chrono::steady_clock::now() - t0;
  done = true;
  for (auto& t : threads) t.join();
  CHECK(took < 5s);  // a hang guard: flush timeout (0.5 s) plus one handler call
  CHECK_FALSE(std::filesystem::exists(server.socket_path()));
  CHECK_THROWS_AS(ctl::ControlClient(server.socket_path()), ctl::ClientError);
  std::filesystem::remove_all(dir);
}

TEST_CASE("socket_group: 0660, owned by the group, whose members are let in") {
  if (::geteuid() != 0) {
    MESSAGE("SKIPPED: needs root to chown the socket and run a client as another uid");
    return;
  }
  const std::string dir = test_dir();
  TestHandler h;
  auto opt = options_in(dir);
  opt.socket_group = "nogroup";
  ctl::ControlServer server(opt, h);
  server.start();
  struct stat st {};
  REQUIRE(::stat(opt.socket_path.c_str(), &st) == 0);
  CHECK((st.st_mode & 0777) == 0660);
  CHECK(st.st_gid == 65534);
  REQUIRE(::chmod(dir.c_str(), 0755) == 0);
  REQUIRE(::chmod((dir + "/sub").c_str(), 0755) == 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(3);
    try {
      ctl::ControlClient c(opt.socket_path, 2000ms);
      ::_exit(c.request({{"cmd", "status"}})["ok"] == true ? 0 : 1);
    } catch (const ctl::ClientError&) {
      ::_exit(2);
    }
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(server.counters().rejected_peer_credentials == 0);

  auto bad = options_in(dir + "_other");
  bad.socket_group = "no_such_group_crease";
  CHECK_THROWS_WITH_AS(ctl::ControlServer(bad, h), doctest::Contains("unknown group"),
                       ctl::ControlError);
  CHECK_FALSE(std::filesystem::exists(bad.socket_path));
  std::filesystem::remove_all(dir);
  std::filesystem::remove_all(dir + "_other");
}
