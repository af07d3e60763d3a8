// Test support: creased as a child process on a shipped configuration, its output in
// DIR/NAME.log and its control socket DIR/NAME.sock; and the figures its progress lines print.
#pragma once

#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/control/control_client.h"

namespace crease::test {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/crease-split-XXXXXX";
    path = ::mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

inline std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// The DDS domain of this test process (1..200, from its pid): its daemons meet nobody else's.
inline int test_domain() { return 1 + static_cast<int>(::getpid() % 200); }

class Creased {
 public:
  // Starts creased --config CONFIG (relative to config/) with ARGS.
  Creased(std::string name, const fs::path& dir, const std::string& config, const std::vector<std::string>& args)
      : name_(std::move(name)), dir_(dir) {
    std::vector<std::string> argv = {"creased", "--config", std::string(CREASE_SOURCE_DIR) + "/config/" + config,
                                     "--plugin-dir", CREASE_PLUGIN_DIR, "--socket", socket(),
                                     "--report-dir", (dir_ / (name_ + "-reports")).string(), "--log-level", "warn"};
    argv.insert(argv.end(), args.begin(), args.end());
    const std::string log = (dir_ / (name_ + ".log")).string();
    std::fflush(nullptr);  // the child must not write this process's buffered output again
    pid_ = ::fork();
    REQUIRE(pid_ >= 0);
    if (pid_ == 0) {
      std::freopen(log.c_str(), "w", stdout);
      std::freopen(log.c_str(), "a", stderr);
      std::vector<char*> cargv;
      for (std::string& a : argv) cargv.push_back(a.data());
      cargv.push_back(nullptr);
      ::execv(CREASE_BIN_DIR "/creased", cargv.data());
      ::_exit(127);
    }
  }
  ~Creased() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  Creased(const Creased&) = delete;
  Creased& operator=(const Creased&) = delete;

  [[nodiscard]] std::string socket() const { return (dir_ / (name_ + ".sock")).string(); }
  [[nodiscard]] std::string output() const { return slurp(dir_ / (name_ + ".log")); }
  [[nodiscard]] bool running() {
    if (pid_ > 0 && ::waitpid(pid_, &status_, WNOHANG) == pid_) pid_ = -1;
    return pid_ > 0;
  }

  // The reply to CMD once creased answers (configured and running); nullopt if it exited first.
  std::optional<nlohmann::json> request(const char* cmd) {
    using namespace std::chrono_literals;
    for (int i = 0; i < 1200; ++i) {  // a hang guard (60 s), not a timing requirement
      if (!running()) return std::nullopt;
      try {
        control::ControlClient c(socket());
        return c.request({{"cmd", cmd}})["result"];
      } catch (const control::ClientError&) {
        std::this_thread::sleep_for(50ms);
      }
    }
    return std::nullopt;
  }
  // The entry named NAME of a list reply (loops, plugins, ports); null when none.
  nlohmann::json entry(const char* cmd, const std::string& name) {
    const auto r = request(cmd);
    if (r)
      for (const auto& e : *r)
        if (e["name"] == name) return e;
    return nullptr;
  }

  // SIGKILL: no goodbye to its peers.
  void kill() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, &status_, 0);
      pid_ = -1;
    }
  }
  // SIGTERM (a clean stop: safe outputs, summary, reports); its exit status, -1 if abnormal.
  int stop() {
    if (pid_ > 0) ::kill(pid_, SIGTERM);
    return wait_exit();
  }
  int wait_exit() {
    if (pid_ > 0) {
      REQUIRE(::waitpid(pid_, &status_, 0) == pid_);
      pid_ = -1;
    }
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1;
  }

 private:
  std::string name_;
  fs::path dir_;
  pid_t pid_ = -1;
  int status_ = 0;
};

// A count of an entry of a list reply (Creased::entry: a port's "writes", a loop's "cycles");
// 0 when there is no such entry.
inline std::uint64_t number(const nlohmann::json& entry, const char* key) {
  return entry.is_null() ? 0 : entry[key].get<std::uint64_t>();
}

// The tracking error of a creased's summary: mean, model frames, last (mm).
struct TrackingSummary {
  double mean_mm = -1;
  int frames = 0;
  double last_mm = -1;
};
inline std::optional<TrackingSummary> tracking_summary(const std::string& out) {
  std::smatch m;
  if (!std::regex_search(out, m,
                         std::regex("tracking error of sheet_state vs sheet_truth: mean ([0-9.]+) mm over ([0-9]+) "
                                    "model frames, last ([0-9.]+) mm")))
    return std::nullopt;
  return TrackingSummary{std::stod(m[1]), std::stoi(m[2]), std::stod(m[3])};
}

// The per-second tracking errors of a creased's progress lines, in order: the second's mean,
// or -1 for a second without a model frame.
inline std::vector<double> tracking_per_second(const std::string& out) {
  std::vector<double> v;
  const std::regex re("tracking error of sheet_state vs sheet_truth: (?:([0-9.]+) mm|no model frames) \\(this second\\)");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), re); it != std::sregex_iterator(); ++it)
    v.push_back((*it)[1].matched ? std::stod((*it)[1]) : -1.0);
  return v;
}

}  // namespace crease::test
