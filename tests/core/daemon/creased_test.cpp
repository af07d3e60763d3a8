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
#include "tests/core/daemon/creased_process.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using namespace crease::test::e2e;

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
  // The host counts a fault when its supervisor takes the loop's event, after the instance's
  // state shows it: both are waited for.
  bool stopped = false, counted = false, host_counted = false;
  for (int i = 0; i < 400 && !(stopped && counted && host_counted); ++i) {
    stopped = plugin("heavy")["state"] == "faulted" && plugin("alloc_stop")["state"] == "faulted";
    counted = plugin("alloc")["rt_allocations"].get<std::uint64_t>() > 100;
    host_counted = client.request({{"cmd", "stats"}})["result"]["faults"] == 2;
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
