// End to end: creased runs a test configuration; creasectl swaps a plugin while it runs, sets a
// parameter, reads reports in every format and stops it. Bad configurations exit 2 before
// anything starts (no socket, no report).
#include <doctest/doctest.h>
#include <sched.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <signal.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/control/control_client.h"
#include "rt/thread_placement.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {
const std::string kBin = CREASE_BIN_DIR;

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/crease-e2e-XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path); }
};

std::string config_text(const std::string& extra_plugin = "") {
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
Run sh(const std::string& cmd) {
  Run r;
  FILE* f = popen((cmd + " 2>&1").c_str(), "r");
  REQUIRE(f != nullptr);
  char buf[4096];
  while (std::fgets(buf, sizeof(buf), f) != nullptr) r.out += buf;
  const int rc = pclose(f);
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return r;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
// Starts creased on CFG (its output in DIR/creased.log) with a socket and a report folder, a
// 60 s bound; returns its pid.
pid_t start_creased(const fs::path& dir, const fs::path& cfg, const std::string& sock, const fs::path& reports) {
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
bool wait_for_socket(const std::string& sock) {
  for (int i = 0; i < 400; ++i) {
    if (fs::exists(sock)) {
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
}  // namespace

TEST_CASE("creased runs, creasectl steers it, reports come out in every format") {
  TempDir tmp;
  const fs::path cfg = tmp.path / "test.yaml";
  std::ofstream(cfg) << config_text();
  const std::string sock = (tmp.path / "creased.sock").string();
  const fs::path reports = tmp.path / "reports";
  const pid_t pid = start_creased(tmp.path, cfg, sock, reports);
  REQUIRE(wait_for_socket(sock));
  struct stat st {};
  REQUIRE(::stat(sock.c_str(), &st) == 0);
  CHECK((st.st_mode & 0777) == 0600);

  const std::string ctl = kBin + "/creasectl --socket " + sock + " ";
  auto status = sh(ctl + "status");
  CAPTURE(status.out);
  CHECK(status.status == 0);

  // Swap while running; the count carries on in the new version.
  auto swap = sh(ctl + "swap counter crease_test_counter_v2");
  CHECK(swap.status == 0);
  auto plugins = sh(ctl + "--json plugins");
  CHECK(nlohmann::json::parse(plugins.out)["result"][0]["version"] == "2.0.0");
  // A refused swap leaves the running version alone and exits non-zero with the reason.
  auto bad_swap = sh(ctl + "swap counter crease_test_wrong_abi");
  CHECK(bad_swap.status != 0);
  CHECK(bad_swap.out.find("ABI") != std::string::npos);

  // Parameters: accepted, refused by range, refused by the plugin.
  CHECK(sh(ctl + "param set counter increment 3").status == 0);
  auto get = sh(ctl + "--json param get counter increment");
  CHECK(nlohmann::json::parse(get.out)["result"]["value"] == 3.0);
  CHECK(sh(ctl + "param set counter increment 500").status != 0);
  CHECK(sh(ctl + "param set counter increment 13").status != 0);

  {
    crease::control::ControlClient client(sock);
    const auto r = client.request({{"cmd", "ports"}});
    CHECK(r["ok"] == true);
    bool saw_count = false;
    for (const auto& p : r["result"]) saw_count |= p["name"] == "count" && p["writes"].get<std::uint64_t>() > 0;
    CHECK(saw_count);
  }

  for (const char* fmt : {"html", "json", "text"}) {
    CAPTURE(fmt);
    const fs::path out = tmp.path / (std::string("live.") + fmt);
    auto rep = sh(ctl + "report --format " + fmt + " --out " + out.string());
    CHECK(rep.status == 0);
    const std::string body = slurp(out);
    CHECK(body.size() > 100);
    CHECK(body.find("control") != std::string::npos);
  }
  CHECK(slurp(tmp.path / "live.html").find("<svg") != std::string::npos);
  CHECK(slurp(tmp.path / "live.text").find("# Histogram") != std::string::npos);

  CHECK(sh(ctl + "stop").status == 0);
  int wstatus = 0;
  for (int i = 0; i < 200; ++i) {
    if (waitpid(pid, &wstatus, WNOHANG) == pid) break;
    std::this_thread::sleep_for(25ms);
  }
  REQUIRE(WIFEXITED(wstatus));
  CHECK(WEXITSTATUS(wstatus) == 0);
  CHECK_FALSE(fs::exists(sock));
  for (const char* f : {"report.html", "report.json", "report.txt"}) CHECK(fs::exists(reports / f));
  const std::string json = slurp(reports / "report.json");
  CHECK(json.find("hot_swap") != std::string::npos);
  const std::string log = slurp(tmp.path / "creased.log");
  CHECK(log.find("creasectl stop") != std::string::npos);
  // The swap line names the library swapped in (not only its plugin's name) and the one it replaced.
  CHECK(log.find("swapped 'counter' in loop 'control': libcrease_test_counter_v2.so (test_counter 2.0.0) from /") !=
        std::string::npos);
  CHECK(log.find(", replacing libcrease_test_counter_v1.so") != std::string::npos);

  // After it stopped, creasectl says so and exits non-zero.
  auto gone = sh(ctl + "status");
  CHECK(gone.status != 0);
}

// The control loop pinned to the last CPU: every other thread of the daemon (control server,
// log drain, the host) stays off it, and `threads` and the report say where each one runs.
TEST_CASE("non-real-time threads stay off a pinned loop's CPU; threads view and report show it") {
  cpu_set_t set;
  CPU_ZERO(&set);
  REQUIRE(sched_getaffinity(0, sizeof(set), &set) == 0);
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  REQUIRE(cpus.size() >= 2);  // a machine of one CPU cannot keep a CPU for the loop
  const int rt_cpu = cpus.back();
  const std::string others = crease::rt::format_cpu_list({cpus.begin(), cpus.end() - 1});  // rt.thread_placement tests it

  TempDir tmp;
  const fs::path cfg = tmp.path / "pinned.yaml";
  std::ofstream(cfg) << std::string("plugin_dirs: [") + CREASE_PLUGIN_DIR + "]\n"
                     << "loops:\n  - {name: control, rate_hz: 1000, priority: 0, cpu: " << rt_cpu << "}\n"
                     << "plugins:\n  - {name: counter, library: crease_test_counter_v1, loop: control, order: 1}\n";
  const std::string sock = (tmp.path / "creased.sock").string();
  const fs::path reports = tmp.path / "reports";
  const pid_t pid = start_creased(tmp.path, cfg, sock, reports);
  REQUIRE(wait_for_socket(sock));
  {
    crease::control::ControlClient client(sock);
    // The socket listens before the loops start: ask until the loop's thread is there.
    nlohmann::json r;
    for (int i = 0; i < 400; ++i) {
      r = client.request({{"cmd", "threads"}});
      if (r["result"]["threads"].dump().find("crease-control") != std::string::npos) break;
      std::this_thread::sleep_for(25ms);
    }
    REQUIRE(r["ok"] == true);
    CHECK(r["result"]["non_rt_cpus"] == others);
    bool saw_loop = false, saw_io = false, saw_work = false;
    for (const auto& t : r["result"]["threads"]) {
      CAPTURE(t.dump());
      const std::string name = t["name"];
      if (name == "crease-control") {
        saw_loop = true;
        CHECK(t["cpus"] == std::to_string(rt_cpu));
        continue;
      }
      saw_io |= name == "crease-ctl-io";
      saw_work |= name == "crease-ctl-work";
      CHECK(t["cpus"] == others);  // every other thread: main, control server, log drain, ...
    }
    CHECK(saw_loop);
    CHECK(saw_io);
    CHECK(saw_work);
  }
  const auto human = sh(kBin + "/creasectl --socket " + sock + " threads");
  CHECK(human.status == 0);
  CHECK(human.out.find("crease-ctl-io") != std::string::npos);
  CHECK(sh(kBin + "/creasectl --socket " + sock + " stop").status == 0);
  int wstatus = 0;
  for (int i = 0; i < 200; ++i) {
    if (waitpid(pid, &wstatus, WNOHANG) == pid) break;
    std::this_thread::sleep_for(25ms);
  }
  REQUIRE(WIFEXITED(wstatus));
  const auto report = nlohmann::json::parse(slurp(reports / "report.json"));
  CHECK(report["machine"]["non_rt_cpus"] == others);
  bool reported_loop = false;
  for (const auto& t : report["machine"]["threads"]) {
    if (t["name"] == "crease-control") reported_loop = t["cpus"] == std::to_string(rt_cpu);
  }
  CHECK(reported_loop);
  CHECK(slurp(reports / "report.txt").find("# non-real-time threads on CPUs: " + others) != std::string::npos);
}

// True once PID blocks SIGINT and SIGTERM (main's first step, before anything is built): a
// signal sent from then on is creased's to take, not the default action's.
bool blocks_stop_signals(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("SigBlk:", 0) != 0) continue;
    const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
    return (mask >> (SIGINT - 1) & 1) != 0 && (mask >> (SIGTERM - 1) & 1) != 0;
  }
  return false;
}

// A start-up of 20 plugins that take 0.5 s each to configure (10 s in all), then loops that
// would run: a signal sent as soon as creased takes signals ends it before its next stage,
// no loop runs, and it says so. Without the check between stages it starts everything, runs
// the loops and only then stops ("creased running" in its log).
TEST_CASE("SIGTERM or SIGINT during start-up: creased stops at the next stage, no loop runs, exit 0") {
  for (const int sig : {SIGTERM, SIGINT}) {
    CAPTURE(sig);
    TempDir tmp;
    const fs::path cfg = tmp.path / "slow.yaml";
    {
      std::ofstream out(cfg);
      out << config_text();
      for (int i = 0; i < 20; ++i) {
        out << "  - {name: slow" << i << ", library: crease_test_slow_configure, loop: control, order: " << 10 + i
            << ", params: {configure_ms: 500}, ports: {out: slow" << i << "}}\n";
      }
    }
    const std::string sock = (tmp.path / "creased.sock").string();
    const fs::path reports = tmp.path / "reports";
    const pid_t pid = start_creased(tmp.path, cfg, sock, reports);
    bool blocked = false;
    for (int i = 0; i < 1000 && !blocked; ++i) {
      blocked = blocks_stop_signals(pid);
      if (!blocked) std::this_thread::sleep_for(5ms);
    }
    REQUIRE(blocked);
    const auto t0 = std::chrono::steady_clock::now();
    REQUIRE(::kill(pid, sig) == 0);
    int wstatus = 0;
    bool exited = false;
    for (int i = 0; i < 1200 && !exited; ++i) {  // a hang guard of 60 s, the run's --duration
      exited = waitpid(pid, &wstatus, WNOHANG) == pid;
      if (!exited) std::this_thread::sleep_for(50ms);
    }
    if (!exited) {
      ::kill(pid, SIGKILL);
      waitpid(pid, &wstatus, 0);
    }
    REQUIRE(exited);
    MESSAGE("creased exited " << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()
                              << " s after the signal (its start-up alone is 10 s)");
    const std::string log = slurp(tmp.path / "creased.log");
    CAPTURE(log);
    REQUIRE(WIFEXITED(wstatus));
    CHECK(WEXITSTATUS(wstatus) == 0);
    const std::string said = std::string("creased: stopped by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM") +
                             " during start-up, ";
    REQUIRE(log.find(said) != std::string::npos);
    CHECK(log.find("no loop ran") != std::string::npos);
    CHECK(log.find("creased running") == std::string::npos);
    // It stopped at one of the first stages (the signal is sent while the configuration is
    // read or the first plugins configure), never after the 20 slow plugins were configured.
    const std::string stage = log.substr(log.find(said) + said.size());
    CAPTURE(stage);
    const bool at_config = stage.rfind("after reading the configuration", 0) == 0;
    const bool at_plugin = stage.rfind("before plugin ", 0) == 0 && stage.find(" of 21 (") != std::string::npos &&
                           std::stoi(stage.substr(14)) <= 20;
    CHECK((at_config || at_plugin));
    CHECK_FALSE(fs::exists(sock));
    CHECK_FALSE(fs::exists(reports));
  }
}

// The firewall in the running daemon: a 1500 us plugin in the 1 kHz loop is stopped by its
// time budget (the loop's period by default); an allocating plugin's heap allocations are
// counted for it (creased links the allocation hooks), and with on_rt_allocation: deactivate
// another is stopped. stats, plugins and the report show it.
TEST_CASE("creased stops a plugin over its time budget and counts an allocating plugin's allocations") {
  TempDir tmp;
  const fs::path cfg = tmp.path / "test.yaml";
  std::ofstream(cfg) << config_text(
      "  - {name: heavy, library: crease_test_slow, loop: control, order: 2, params: {busy_us: 1500, after: 0},"
      " ports: {out: heavy_out}}\n"
      "  - {name: alloc, library: crease_test_allocating, loop: control, order: 3, params: {after: 5},"
      " ports: {out: alloc_out}}\n"
      "  - {name: alloc_stop, library: crease_test_allocating, loop: control, order: 4, params: {after: 5},"
      " ports: {out: alloc_stop_out}, on_rt_allocation: deactivate}\n");
  const std::string sock = (tmp.path / "creased.sock").string();
  const fs::path reports = tmp.path / "reports";
  const pid_t pid = start_creased(tmp.path, cfg, sock, reports);
  REQUIRE(wait_for_socket(sock));
  crease::control::ControlClient client(sock);
  auto plugin = [&](const std::string& name) {
    const auto r = client.request({{"cmd", "stats"}});
    for (const auto& p : r["result"]["plugins"]) {
      if (p["name"] == name) return p;
    }
    return nlohmann::json();
  };
  bool stopped = false, counted = false;
  for (int i = 0; i < 400 && !(stopped && counted); ++i) {
    stopped = plugin("heavy")["state"] == "faulted" && plugin("alloc_stop")["state"] == "faulted";
    counted = plugin("alloc")["rt_allocations"].get<std::uint64_t>() > 100;
    std::this_thread::sleep_for(25ms);
  }
  CHECK(stopped);
  CHECK(counted);
  const auto stats = client.request({{"cmd", "stats"}})["result"];
  CHECK(stats["rt_allocations"]["counted"] == true);
  CHECK(stats["faults"] == 2);
  CHECK(plugin("heavy")["over_budget"].get<std::uint64_t>() >= 20);
  CHECK(plugin("heavy")["rt_allocations"] == 0);
  CHECK(plugin("alloc")["state"] == "active");  // safety.on_rt_allocation: count (the default)
  CHECK(plugin("alloc_stop")["rt_allocations"] == 1);
  CHECK(plugin("counter")["rt_allocations"] == 0);
  CHECK(plugin("counter")["state"] == "active");
  const auto plugins = client.request({{"cmd", "plugins"}})["result"];
  for (const auto& p : plugins) {
    if (p["name"] == "heavy") {
      CHECK(p["budget_us"] == 1000.0);
      CHECK(p["budget_cycles"] == 20);
      CHECK(p["last_fault"] == "ran over its time budget");
    }
  }
  CHECK(sh(kBin + "/creasectl --socket " + sock + " stop").status == 0);
  int wstatus = 0;
  for (int i = 0; i < 200; ++i) {
    if (waitpid(pid, &wstatus, WNOHANG) == pid) break;
    std::this_thread::sleep_for(25ms);
  }
  REQUIRE(WIFEXITED(wstatus));
  const std::string log = slurp(tmp.path / "creased.log");
  CHECK(log.find("instance 'heavy' in loop 'control' ran over its time budget (1000 us) for 20 consecutive cycles") !=
        std::string::npos);
  const auto report = nlohmann::json::parse(slurp(reports / "report.json"));
  std::uint64_t alloc_in_report = 0;
  for (const auto& l : report["loops"]) {
    for (const auto& p : l["plugins"]) {
      if (p["name"] == "alloc") alloc_in_report = p["rt_allocations"].get<std::uint64_t>();
    }
  }
  CHECK(alloc_in_report > 100);
  CHECK(slurp(reports / "report.txt").find("rt_allocations=") != std::string::npos);
}

TEST_CASE("bad configurations exit 2 with file, line and key, and start nothing") {
  TempDir tmp;
  struct Case {
    std::string text;
    std::string expect;
  };
  const std::vector<Case> cases = {
      {config_text("    params: {increment: 500}\n"), "test.yaml:9:25: plugins[0].params.increment: must be in [0, 100], got 500"},
      {config_text("    params: {incremnt: 5}\n"), "plugins[0].params.incremnt: unknown parameter"},
      {config_text("    ports: {cuont: x}\n"), "ports.cuont: the plugin has no port 'cuont'"},
      {config_text("  - {name: wrong, library: crease_test_wrong_abi, loop: control, order: 2}\n"),
       "plugins[1] 'wrong': plugin library"},
      {config_text("  - {name: other, library: crease_test_counter_v2, loop: control, order: 2}\n"),
       "port 'count': instance 'other' cannot write it: instance 'counter' already does"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.text);
    const fs::path cfg = tmp.path / "test.yaml";
    std::ofstream(cfg) << c.text;
    const std::string sock = (tmp.path / "s.sock").string();
    auto r = sh(kBin + "/creased --config " + cfg.string() + " --socket " + sock + " --report-dir " +
                (tmp.path / "rep").string() + " --duration 5");
    CHECK(r.status == 2);
    CHECK(r.out.find(c.expect) != std::string::npos);
    CHECK_FALSE(fs::exists(sock));
    CHECK_FALSE(fs::exists(tmp.path / "rep"));
  }
}
