// Two simulated robots on one machine: two creased processes run config/sim.yaml at the same
// time, each on its own mocked buses (bus_prefix: auto, crease-sim-<pid>-*), and both end with
// 0 faults. With one fixed prefix shared by both, the second would be refused at configure
// (its bus name is taken): the second case shows the buses are derived from the daemon's pid
// by taking one of them first.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "core/control/control_client.h"
#include "drivers/can/mock_can_broker.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/crease-two-XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path); }
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// One creased on config/sim.yaml, its output in NAME.log, its socket NAME.sock. The child
// waits for a byte on a pipe before it execs, so the test knows its pid (and so its bus
// prefix) first.
struct Robot {
  std::string name;
  fs::path dir;
  pid_t pid = -1;   // -1 once reaped
  int gate = -1;    // write end: one byte lets the child exec creased
  std::string prefix;  // its buses' prefix under bus_prefix: auto

  Robot(std::string n, const fs::path& d) : name(std::move(n)), dir(d) {
    int fds[2];
    REQUIRE(::pipe(fds) == 0);
    const std::string log = (dir / (name + ".log")).string();
    const std::string sock = socket();
    const std::string reports = (dir / (name + "-reports")).string();
    std::fflush(nullptr);  // the child must not write this process's buffered output again
    pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      ::close(fds[1]);
      char go = 0;
      if (::read(fds[0], &go, 1) != 1) _exit(126);
      std::freopen(log.c_str(), "w", stdout);
      std::freopen(log.c_str(), "a", stderr);
      // The duration only bounds a run the test fails to stop.
      execl(CREASE_BIN_DIR "/creased", "creased", "--config", CREASE_SOURCE_DIR "/config/sim.yaml", "--plugin-dir",
            CREASE_PLUGIN_DIR, "--socket", sock.c_str(), "--report-dir", reports.c_str(), "--duration", "30",
            "--no-progress", "--log-level", "warn", static_cast<char*>(nullptr));
      _exit(127);
    }
    ::close(fds[0]);
    gate = fds[1];
    prefix = "crease-sim-" + std::to_string(pid);
  }
  ~Robot() {
    if (gate >= 0) ::close(gate);
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }

  [[nodiscard]] std::string socket() const { return (dir / (name + ".sock")).string(); }
  [[nodiscard]] std::string output() const { return slurp(dir / (name + ".log")); }

  void start() {
    REQUIRE(::write(gate, "g", 1) == 1);
    ::close(gate);
    gate = -1;
  }

  // The reply to CMD once creased answers (configured and running); nullopt if it exited first.
  std::optional<nlohmann::json> request_when_up(const char* cmd) {
    for (int i = 0; i < 1200; ++i) {  // a hang guard (60 s), not a timing requirement
      if (::waitpid(pid, &status_, WNOHANG) == pid) {
        pid = -1;
        return std::nullopt;
      }
      try {
        crease::control::ControlClient c(socket());
        return c.request({{"cmd", cmd}});
      } catch (const crease::control::ClientError&) {
        std::this_thread::sleep_for(50ms);
      }
    }
    return std::nullopt;
  }

  // Cycles of loop LOOP so far.
  std::uint64_t cycles(const std::string& loop) {
    const auto r = request_when_up("loops");
    REQUIRE(r);
    for (const auto& l : (*r)["result"])
      if (l["name"] == loop) return l["cycles"].get<std::uint64_t>();
    FAIL("no loop " << loop);
    return 0;
  }

  // Sends stop and returns creased's exit status (-1 if it did not exit normally).
  int stop() {
    if (pid > 0) {
      crease::control::ControlClient c(socket());
      (void)c.request({{"cmd", "stop"}});
    }
    return wait_exit();
  }
  int wait_exit() {
    if (pid > 0) {
      REQUIRE(::waitpid(pid, &status_, 0) == pid);
      pid = -1;
    }
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1;
  }

 private:
  int status_ = 0;
};

}  // namespace

TEST_CASE("two creased on config/sim.yaml at once: each on its own buses, both 0 faults") {
  TempDir tmp;
  Robot a("a", tmp.path), b("b", tmp.path);
  a.start();
  b.start();
  // Both answer: both configured their buses and run at the same time.
  const auto sa = a.request_when_up("status");
  const auto sb = b.request_when_up("status");
  INFO("a: " << a.output());
  INFO("b: " << b.output());
  REQUIRE(sa);
  REQUIRE(sb);
  // Let the drivers and devices of both talk for 2 s of control cycles each.
  while (a.cycles("control") < 2000 || b.cycles("control") < 2000) std::this_thread::sleep_for(100ms);
  CHECK(a.stop() == 0);
  CHECK(b.stop() == 0);
  for (const Robot* r : {&a, &b}) {
    const std::string out = r->output();
    CAPTURE(r->name);
    CHECK(out.find("Address already in use") == std::string::npos);
    CHECK(out.find("faults: 0") != std::string::npos);
  }
}

TEST_CASE("the buses are the daemon's own: crease-sim-<pid>-*, a taken name refused naming the key") {
  TempDir tmp;
  Robot a("a", tmp.path);
  // Take a bus a's world will create, as a second robot with a shared prefix would.
  crease::drivers::MockCanBroker taken({a.prefix + "-arm_r", 0, 0, false});
  a.start();
  CHECK(a.wait_exit() == 2);  // a configuration error: nothing started
  const std::string out = a.output();
  INFO(out);
  CHECK(out.find("plugins[2].params.bus_prefix:") != std::string::npos);
  CHECK(out.find("sim.yaml:") != std::string::npos);
  CHECK(out.find(a.prefix + "-arm_r") != std::string::npos);
  CHECK(out.find("Address already in use") != std::string::npos);
}
