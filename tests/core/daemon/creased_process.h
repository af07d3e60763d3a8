// Shared by the end-to-end tests of creased (tests/core/daemon): a temporary folder, the test
// configuration, creased started as a child process with its output in a log, and the checks
// on a running process they share.
#pragma once

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

namespace crease::test::e2e {

using namespace std::chrono_literals;

inline const std::string kBin = CREASE_BIN_DIR;

struct TempDir {
  std::filesystem::path path;
  TempDir() {
    char tmpl[] = "/tmp/crease-e2e-XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
};

inline std::string config_text(const std::string& extra_plugin = "") {
  return std::string("plugin_dirs: [") + CREASE_PLUGIN_DIR + "]\n"
         "loops:\n"
         "  - {name: control, rate_hz: 1000, priority: 0}\n"
         "plugins:\n"
         "  - name: counter\n"
         "    library: crease_test_counter_v1\n"
         "    loop: control\n"
         "    order: 1\n" +
         extra_plugin;
}

struct Run {
  int status = -1;
  std::string out;
};

// Runs a shell command, returns its exit status and output (stdout + stderr).
inline Run sh(const std::string& cmd) {
  Run r;
  FILE* f = popen((cmd + " 2>&1").c_str(), "r");
  REQUIRE(f != nullptr);
  char buf[4096];
  while (std::fgets(buf, sizeof(buf), f) != nullptr) r.out += buf;
  const int rc = pclose(f);
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return r;
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// Starts creased on CFG (its output in DIR/creased.log) with a socket and a report folder, a
// 60 s bound; returns its pid.
inline pid_t start_creased(const std::filesystem::path& dir, const std::filesystem::path& cfg, const std::string& sock, const std::filesystem::path& reports) {
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    const std::string out = (dir / "creased.log").string();
    std::freopen(out.c_str(), "w", stdout);
    std::freopen(out.c_str(), "a", stderr);
    execl((kBin + "/creased").c_str(), "creased", "--config", cfg.c_str(), "--socket", sock.c_str(), "--report-dir",
          reports.c_str(), "--duration", "60", "--no-progress", static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// Waits (at most 10 s) until creased listens on SOCK (the file exists from bind(), a moment
// before listen(): a connection in between is refused).
inline bool wait_for_socket(const std::string& sock) {
  for (int i = 0; i < 400; ++i) {
    if (std::filesystem::exists(sock)) {
      try {
        crease::control::ControlClient probe(sock);
        return true;
      } catch (const crease::control::ClientError&) {
      }
    }
    std::this_thread::sleep_for(25ms);
  }
  return false;
}

// True once PID blocks SIGINT and SIGTERM (main's first step, before anything is built): a
// signal sent from then on is creased's to take, not the default action's.
inline bool blocks_stop_signals(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("SigBlk:", 0) != 0) continue;
    const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
    return (mask >> (SIGINT - 1) & 1) != 0 && (mask >> (SIGTERM - 1) & 1) != 0;
  }
  return false;
}

// Waits for PID to exit, at most LIMIT (then kills it); its wait status, or nullopt when it had
// to be killed.
inline std::optional<int> wait_exit(pid_t pid, std::chrono::milliseconds limit) {
  int wstatus = 0;
  for (auto waited = 0ms; waited < limit; waited += 20ms) {
    if (waitpid(pid, &wstatus, WNOHANG) == pid) return wstatus;
    std::this_thread::sleep_for(20ms);
  }
  ::kill(pid, SIGKILL);
  waitpid(pid, &wstatus, 0);
  return std::nullopt;
}

}  // namespace crease::test::e2e
