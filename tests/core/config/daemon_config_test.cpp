// Tests for core/config/daemon_config.h: a good file, then many bad ones, each with the exact
// message (file, 1-based line and column, key path, reason) the user will read.
#include "core/config/daemon_config.h"

#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace cfg = crease::config;

namespace {

const cfg::LoadOptions kNoDirCheck{false};

std::string error_of(const std::string& text, const cfg::LoadOptions& options = kNoDirCheck) {
  try {
    (void)cfg::load_daemon_config_from_string(text, "/etc/crease/bad.yaml", options);
  } catch (const cfg::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

const char* const kGood = R"(plugin_dirs: [../plugins-lib, /opt/crease/plugins]
daemon:
  socket: run/creased.sock
  socket_group: crease
  report_dir: reports
  duration_s: 30
  lock_memory: false
  prefault_heap_mb: 16
  cpu_dma_latency_us: 0
  non_rt_cpus: [0]
loops:
  - name: control
    rate_hz: 1000
    priority: 80
    cpu: 1
    overrun: skip
  - name: model
    rate_hz: 60
    priority: 0
plugins:
  - name: second
    library: crease_counter
    loop: control
    order: 20
    params: {step: 2, nested: {a: [1, 2]}}
    ports: {out: counter_b}
  - name: first
    library: ./libs/libcustom.so
    loop: control
    order: 10
    enabled: false
  - name: modeller
    library: crease_counter
    loop: model
    order: 10
safety:
  on_fault: stop
  max_overruns_per_s: 5
)";

}  // namespace

TEST_CASE("a complete configuration loads into plain structs with resolved paths and marks") {
  const cfg::DaemonConfig c =
      cfg::load_daemon_config_from_string(kGood, "/etc/crease/sim.yaml", kNoDirCheck);
  CHECK(c.file == "/etc/crease/sim.yaml");
  REQUIRE(c.plugin_dirs.size() == 2);
  CHECK(c.plugin_dirs[0] == "/etc/plugins-lib");
  CHECK(c.plugin_dirs[1] == "/opt/crease/plugins");
  CHECK(c.daemon.socket.value() == "/etc/crease/run/creased.sock");
  CHECK(c.daemon.socket_group.value() == "crease");
  CHECK(c.daemon.report_dir.value() == "/etc/crease/reports");
  CHECK(c.daemon.duration_s.value() == doctest::Approx(30.0));
  CHECK_FALSE(c.daemon.lock_memory);
  CHECK(c.daemon.prefault_heap_mb == 16);
  CHECK(c.daemon.cpu_dma_latency_us.value() == 0);
  REQUIRE(c.daemon.non_rt_cpus.has_value());
  CHECK(*c.daemon.non_rt_cpus == std::vector<int>{0});

  REQUIRE(c.loops.size() == 2);
  CHECK(c.loops[0].name == "control");
  CHECK(c.loops[0].rate_hz == doctest::Approx(1000.0));
  CHECK(c.loops[0].period_ns() == 1000000);
  CHECK(c.loops[0].priority == 80);
  CHECK(c.loops[0].cpu == 1);
  CHECK(c.loops[0].loc.line == 12);
  CHECK(c.loops[0].loc.column == 5);
  CHECK(c.loops[1].cpu == -1);
  CHECK(c.loops[1].period_ns() == 16666667);

  REQUIRE(c.plugins.size() == 3);
  const cfg::PluginConfig* second = c.find_plugin("second");
  REQUIRE(second != nullptr);
  CHECK(second->library == "crease_counter");
  CHECK(second->enabled);
  CHECK(second->params["step"].as<int>() == 2);
  CHECK(second->params["nested"]["a"][1].as<int>() == 2);
  CHECK(second->params_loc.line == 25);
  CHECK(second->ports.at("out") == "counter_b");
  CHECK(second->loc.str() == "/etc/crease/sim.yaml:21:5");
  CHECK(c.find_plugin("first")->library == "/etc/crease/libs/libcustom.so");
  CHECK_FALSE(c.find_plugin("first")->enabled);
  CHECK(c.find_plugin("modeller")->params.IsMap());
  CHECK(c.find_plugin("nope") == nullptr);

  const auto ordered = c.plugins_of_loop("control");
  REQUIRE(ordered.size() == 2);
  CHECK(ordered[0]->name == "first");
  CHECK(ordered[1]->name == "second");
  CHECK(c.safety.on_fault == cfg::FaultPolicy::stop);
  CHECK(c.safety.max_overruns_per_s == doctest::Approx(5.0));
}

TEST_CASE("a loop's phase: its deadlines' offset on its period's grid, in ns") {
  const cfg::DaemonConfig c = cfg::load_daemon_config_from_string(
      "plugin_dirs: [p]\nloops:\n  - {name: a, rate_hz: 1000, priority: 0}\n"
      "  - {name: b, rate_hz: 1000, priority: 0, phase_us: 500}\n",
      "x.yaml", kNoDirCheck);
  CHECK(c.loops[0].phase_ns == 0);
  CHECK(c.loops[1].phase_ns == 500'000);
}

TEST_CASE("defaults: optional sections may be absent") {
  const cfg::DaemonConfig c = cfg::load_daemon_config_from_string(
      "plugin_dirs: [p]\nloops: [{name: a, rate_hz: 10, priority: 0}]\n", "x.yaml", kNoDirCheck);
  CHECK(c.plugin_dirs[0] == "p");
  CHECK_FALSE(c.daemon.socket.has_value());
  CHECK_FALSE(c.daemon.duration_s.has_value());
  CHECK_FALSE(c.daemon.cpu_dma_latency_us.has_value());
  CHECK_FALSE(c.daemon.non_rt_cpus.has_value());
  CHECK(c.daemon.lock_memory);
  CHECK(c.plugins.empty());
  CHECK(c.safety.on_fault == cfg::FaultPolicy::deactivate);
  CHECK(c.safety.max_overruns_per_s == 0.0);
}

// Each bad file shares this head (lines 1-5); the cases append or replace lines.
#define HEAD "plugin_dirs: [p]\nloops:\n  - name: control\n    rate_hz: 1000\n    priority: 80\n"

TEST_CASE("bad configurations name file, line, column, key and reason") {
  struct Case {
    const char* what;
    const char* text;
    const char* expected;
  };
  const Case cases[] = {
      {"unknown top-level key", HEAD "plugin: []\n",
       "/etc/crease/bad.yaml:6:1: plugin: unknown key 'plugin' (did you mean 'plugins'?)"},
      {"typo in a loop key", "plugin_dirs: [p]\nloops:\n  - name: control\n    rat_hz: 1000\n",
       "/etc/crease/bad.yaml:4:5: loops[0].rat_hz: unknown key 'rat_hz' (did you mean 'rate_hz'?)"},
      {"rate zero", "plugin_dirs: [p]\nloops:\n  - name: control\n    rate_hz: 0\n    priority: 1\n",
       "/etc/crease/bad.yaml:4:14: loops[0].rate_hz: must be in (0, 20000], got 0"},
      {"rate too high", "plugin_dirs: [p]\nloops:\n  - {name: a, rate_hz: 30000, priority: 1}\n",
       "/etc/crease/bad.yaml:3:24: loops[0].rate_hz: must be in (0, 20000], got 30000"},
      {"priority out of range", "plugin_dirs: [p]\nloops:\n  - name: c\n    rate_hz: 10\n    priority: 120\n",
       "/etc/crease/bad.yaml:5:15: loops[0].priority: must be in [0, 99], got 120"},
      {"priority not an integer", "plugin_dirs: [p]\nloops:\n  - name: c\n    rate_hz: 10\n    priority: high\n",
       "/etc/crease/bad.yaml:5:15: loops[0].priority: expected an integer, got 'high'"},
      {"cpu out of range", HEAD "    cpu: 2048\n",
       "/etc/crease/bad.yaml:6:10: loops[0].cpu: must be in [-1, 1023], got 2048"},
      {"unknown overrun policy", HEAD "    overrun: catch_up\n",
       "/etc/crease/bad.yaml:6:14: loops[0].overrun: unknown overrun policy 'catch_up' (only 'skip' is supported)"},
      {"duplicate loop name", HEAD "  - name: control\n    rate_hz: 10\n    priority: 1\n",
       "/etc/crease/bad.yaml:6:11: loops[1].name: duplicate loop name 'control' (first at /etc/crease/bad.yaml:3:5)"},
      {"invalid loop name", "plugin_dirs: [p]\nloops:\n  - name: Control\n    rate_hz: 10\n    priority: 1\n",
       "/etc/crease/bad.yaml:3:11: loops[0].name: 'Control' is not a valid name ([a-z][a-z0-9_]*)"},
      {"plugin on an unknown loop",
       HEAD "plugins:\n  - name: counter\n    library: crease_counter\n    loop: contrl\n    order: 1\n",
       "/etc/crease/bad.yaml:9:11: plugins[0].loop: unknown loop 'contrl' (did you mean 'control'?)"},
      {"order tie",
       HEAD "plugins:\n  - {name: a, library: x, loop: control, order: 5}\n"
            "  - {name: b, library: x, loop: control, order: 5}\n",
       "/etc/crease/bad.yaml:8:49: plugins[1].order: order 5 is already used by 'a' in loop 'control'"},
      {"missing library", HEAD "plugins:\n  - name: a\n    loop: control\n    order: 1\n",
       "/etc/crease/bad.yaml:7:5: plugins[0].library: required key is missing"},
      {"params not a map", HEAD "plugins:\n  - {name: a, library: x, loop: control, order: 1, params: [1, 2]}\n",
       "/etc/crease/bad.yaml:7:60: plugins[0].params: expected a map"},
      {"empty plugin_dirs", "plugin_dirs: []\nloops: [{name: a, rate_hz: 1, priority: 0}]\n",
       "/etc/crease/bad.yaml:1:14: plugin_dirs: expected a non-empty list of folders"},
      {"missing loops", "plugin_dirs: [p]\nplugins: []\n",
       "/etc/crease/bad.yaml:1:1: loops: required key is missing"},
      {"YAML syntax error", "plugin_dirs: [p\nloops: []\n",
       "/etc/crease/bad.yaml:2:6: (syntax): end of sequence flow not found"},
      {"unknown fault policy", HEAD "safety:\n  on_fault: explode\n",
       "/etc/crease/bad.yaml:7:13: safety.on_fault: expected 'deactivate' or 'stop', got 'explode'"},
      {"negative duration", HEAD "daemon:\n  duration_s: -1\n",
       "/etc/crease/bad.yaml:7:15: daemon.duration_s: must be in (0, 1e+09], got -1"},
      {"duplicate key", HEAD "    priority: 10\n",
       "/etc/crease/bad.yaml:6:5: loops[0].priority: duplicate key 'priority'"},
      {"enabled not a bool", HEAD "plugins:\n  - {name: a, library: x, loop: control, order: 1, enabled: maybe}\n",
       "/etc/crease/bad.yaml:7:61: plugins[0].enabled: expected true or false, got 'maybe'"},
      {"duplicate plugin name",
       HEAD "plugins:\n  - {name: a, library: x, loop: control, order: 1}\n"
            "  - {name: a, library: x, loop: control, order: 2}\n",
       "/etc/crease/bad.yaml:8:12: plugins[1].name: duplicate plugin name 'a' (first at /etc/crease/bad.yaml:7:5)"},
      {"top level is a list", "- a\n- b\n",
       "/etc/crease/bad.yaml:1:1: (document): expected a map with plugin_dirs, loops and plugins"},
      {"port map not a map", HEAD "plugins:\n  - {name: a, library: x, loop: control, order: 1, ports: out}\n",
       "/etc/crease/bad.yaml:7:59: plugins[0].ports: expected a map local: global"},
      {"non_rt_cpus empty", HEAD "daemon:\n  non_rt_cpus: []\n",
       "/etc/crease/bad.yaml:7:16: daemon.non_rt_cpus: expected a non-empty list of CPU indices, e.g. [0]"},
      {"non_rt_cpus out of range", HEAD "daemon:\n  non_rt_cpus: [0, 4096]\n",
       "/etc/crease/bad.yaml:7:20: daemon.non_rt_cpus[1]: must be in [0, 1023], got 4096"},
      {"socket is a list", HEAD "daemon:\n  socket: [a]\n",
       "/etc/crease/bad.yaml:7:11: daemon.socket: expected a string, got a list"},
      {"duplicate key inside params",
       HEAD "plugins:\n  - name: a\n    library: x\n    loop: control\n    order: 1\n"
            "    params:\n      pid: {kp: 1, kp: 2}\n",
       "/etc/crease/bad.yaml:12:20: plugins[0].params.pid.kp: duplicate key 'kp'"},
      {"nan rate", "plugin_dirs: [p]\nloops:\n  - {name: a, rate_hz: .nan, priority: 1}\n",
       "/etc/crease/bad.yaml:3:24: loops[0].rate_hz: expected a finite number, got '.nan'"},
      {"phase of a whole period", "plugin_dirs: [p]\nloops:\n  - {name: a, rate_hz: 1000, priority: 1, phase_us: 1000}\n",
       "/etc/crease/bad.yaml:3:53: loops[0].phase_us: must be below the loop's period (1000 us)"},
      {"negative phase", "plugin_dirs: [p]\nloops:\n  - {name: a, rate_hz: 1000, priority: 1, phase_us: -1}\n",
       "/etc/crease/bad.yaml:3:53: loops[0].phase_us: must be in [0, 1000], got -1"},
  };
  static_assert(sizeof(cases) / sizeof(cases[0]) >= 15);
  for (const Case& c : cases) {
    CAPTURE(c.what);
    CHECK(error_of(c.text) == c.expected);
  }
}

TEST_CASE("plugin_dirs must exist when checked, resolved against the file's folder") {
  const std::string dir = std::filesystem::temp_directory_path() /
                          ("crease_cfg_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir + "/plugins");
  const std::string file = dir + "/good.yaml";
  {
    std::ofstream out(file);
    out << "plugin_dirs: [plugins, missing]\nloops: [{name: a, rate_hz: 1, priority: 0}]\n";
  }
  try {
    (void)cfg::load_daemon_config(file);
    FAIL("expected a ConfigError");
  } catch (const cfg::ConfigError& e) {
    CHECK(std::string(e.what()) == file + ":1:24: plugin_dirs[1]: '" + dir +
                                       "/missing' is not a directory");
    CHECK(e.loc().line == 1);
    CHECK(e.key_path() == "plugin_dirs[1]");
  }
  // The loader's errors are Crease's one ConfigError: what creased and plugins catch.
  static_assert(std::is_same_v<cfg::ConfigError, crease::ConfigError>);
  try {
    (void)cfg::load_daemon_config(file);
    FAIL("expected a ConfigError");
  } catch (const crease::Error& e) {
    CHECK(std::string(e.what()).find("plugin_dirs[1]") != std::string::npos);
  }
  {
    std::ofstream out(file);
    out << "plugin_dirs: [plugins]\nloops: [{name: a, rate_hz: 1, priority: 0}]\n";
  }
  const cfg::DaemonConfig c = cfg::load_daemon_config(file);
  CHECK(c.plugin_dirs.at(0) == dir + "/plugins");
  std::filesystem::remove_all(dir);

  CHECK(error_of("", kNoDirCheck).find("(document)") != std::string::npos);
  try {
    (void)cfg::load_daemon_config(dir + "/does_not_exist.yaml");
    FAIL("expected a ConfigError");
  } catch (const cfg::ConfigError& e) {
    CHECK(std::string(e.what()).find("cannot read") != std::string::npos);
  }
}

TEST_CASE("error_at lets a plugin point into the config for a bad parameter") {
  const cfg::DaemonConfig c = cfg::load_daemon_config_from_string(
      HEAD "plugins:\n  - name: a\n    library: x\n    loop: control\n    order: 1\n"
           "    params:\n      gain: -3\n",
      "sim.yaml", kNoDirCheck);
  const auto& p = c.plugins.at(0);
  const cfg::ConfigError e =
      cfg::error_at(c.file, p.params["gain"], "plugins[0].params.gain", "must be positive");
  CHECK(std::string(e.what()) == "sim.yaml:12:13: plugins[0].params.gain: must be positive");
}

TEST_CASE("--set INSTANCE.KEY=VALUE overrides one plugin parameter; a bad assignment names itself") {
  auto c = cfg::load_daemon_config_from_string(kGood, "/etc/crease/set.yaml", kNoDirCheck);
  cfg::override_param(c, "second.record=/tmp/state.jsonl");
  cfg::override_param(c, "second.step=3");
  cfg::override_param(c, "modeller.gain=2.5");  // an instance without params gains a map
  CHECK(c.plugins[0].params["record"].as<std::string>() == "/tmp/state.jsonl");
  CHECK(c.plugins[0].params["step"].as<int>() == 3);
  CHECK(c.plugins[0].params["nested"]["a"][1].as<int>() == 2);  // the others untouched
  CHECK(c.plugins[2].params["gain"].as<double>() == 2.5);
  for (const char* bad : {"nobody.k=1", "second", "second.=1", ".k=1", "secondk=1"}) {
    CAPTURE(bad);
    try {
      cfg::override_param(c, bad);
      FAIL("must throw");
    } catch (const crease::ConfigError& e) {
      CHECK(std::string(e.what()).find(std::string("--set '") + bad + "'") != std::string::npos);
    }
  }
}

TEST_CASE("bounded: an alias bomb in params and a 50 MB file are refused at where the limit is crossed") {
  // 10^10 leaves inside a plugin's params; every walk of them (the duplicate-key check, the
  // plugin's) would take hours. Refused at the alias on line 16 (l4) where 100,000 nodes are passed.
  std::string bomb = HEAD "plugins:\n  - name: a\n    library: x\n    loop: control\n    order: 1\n"
                          "    params:\n      l0: &l0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int k = 1; k < 10; ++k) {
    const std::string prev = "*l" + std::to_string(k - 1);
    bomb += "      l" + std::to_string(k) + ": &l" + std::to_string(k) + " [" + prev;
    for (int i = 1; i < 10; ++i) bomb += ", " + prev;
    bomb += "]\n";
  }
  const std::string e = error_of(bomb);
  CAPTURE(e);
  CHECK(e.find("/etc/crease/bad.yaml:16:") == 0);
  CHECK(e.find(": plugins[0].params.l4[") != std::string::npos);
  CHECK(e.find("more than 100000 nodes with aliases expanded") != std::string::npos);

  // A 50 MB file (a valid configuration, then comments): refused after reading 1 MiB + 1 byte.
  const std::string dir = std::filesystem::temp_directory_path() / ("crease_cfg_big_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/big.yaml";
  {
    std::ofstream out(file);
    out << "plugin_dirs: [.]\nloops: [{name: a, rate_hz: 1, priority: 0}]\n";
    const std::string comment = "# " + std::string(98, 'c') + "\n";  // 101 bytes a line
    for (int i = 0; i < 500'000; ++i) out << comment;
  }
  REQUIRE(std::filesystem::file_size(file) > 50'000'000);
  try {
    (void)cfg::load_daemon_config(file);
    FAIL("expected a ConfigError");
  } catch (const cfg::ConfigError& ce) {
    // Byte 1048577: after the two lines of 17 and 45 bytes and 10381 lines of comment, the
    // 35th byte of the next one.
    CHECK(std::string(ce.what()) == file + ":10384:35: (file): larger than 1048576 bytes (the limit of a configuration file)");
  }
  // A file without an end is refused the same way.
  try {
    (void)cfg::load_daemon_config("/dev/zero");
    FAIL("expected a ConfigError");
  } catch (const cfg::ConfigError& ce) {
    CHECK(std::string(ce.what()).find("/dev/zero:1:1048577: (file): larger than") == 0);
  }
  // The bounds are options: the same file loads with a larger size limit.
  cfg::LoadOptions roomy{false};
  roomy.bounds.max_bytes = 64u << 20;
  CHECK(cfg::load_daemon_config(file, roomy).loops.at(0).name == "a");
  std::filesystem::remove_all(dir);
}

TEST_CASE("daemon.control: the control socket's limits per client, defaults on") {
  const auto d = cfg::load_daemon_config_from_string(HEAD, "c.yaml", kNoDirCheck).daemon.control;
  CHECK(d.idle_timeout_s == doctest::Approx(30.0));
  CHECK(d.max_requests_per_s == doctest::Approx(500.0));
  CHECK(d.max_clients == 128);
  const auto c = cfg::load_daemon_config_from_string(
                     HEAD "daemon: {control: {idle_timeout_s: 0.5, max_requests_per_s: 0, max_clients: 4}}\n", "c.yaml",
                     kNoDirCheck)
                     .daemon.control;
  CHECK(c.idle_timeout_s == doctest::Approx(0.5));
  CHECK(c.max_requests_per_s == 0.0);
  CHECK(c.max_clients == 4);
  CHECK(error_of(HEAD "daemon: {control: {idle_timeout_s: -1}}\n") ==
        "/etc/crease/bad.yaml:6:36: daemon.control.idle_timeout_s: must be in [0, 86400], got -1");
  CHECK(error_of(HEAD "daemon: {control: {max_clients: 0}}\n").find("daemon.control.max_clients: must be in [1, 4096]") !=
        std::string::npos);
  CHECK(error_of(HEAD "daemon: {control: {rate: 5}}\n").find("daemon.control.rate: unknown key 'rate'") !=
        std::string::npos);
}

TEST_CASE("daemon.startup_stop_grace_s: how long a start-up stage may outlast a stop, 0.5 s by default") {
  CHECK(cfg::load_daemon_config_from_string(HEAD, "c.yaml", kNoDirCheck).daemon.startup_stop_grace_s ==
        doctest::Approx(0.5));
  CHECK(cfg::load_daemon_config_from_string(HEAD "daemon: {startup_stop_grace_s: 0}\n", "c.yaml", kNoDirCheck)
            .daemon.startup_stop_grace_s == 0.0);
  CHECK(error_of(HEAD "daemon: {startup_stop_grace_s: -1}\n") ==
        "/etc/crease/bad.yaml:6:32: daemon.startup_stop_grace_s: must be in [0, 3600], got -1");
}

TEST_CASE("the firewall's limits per instance: budget {time_us, cycles} and on_rt_allocation, with safety's default") {
  const std::string head = HEAD;
  const auto c = cfg::load_daemon_config_from_string(
      head + "plugins:\n"
             "  - {name: a, library: x, loop: control, order: 1, budget: {time_us: 250.5, cycles: 3}}\n"
             "  - {name: b, library: x, loop: control, order: 2, budget: {time_us: 0}, on_rt_allocation: count}\n"
             "  - {name: c, library: x, loop: control, order: 3}\n"
             "safety: {on_rt_allocation: deactivate}\n",
      "/etc/crease/fw.yaml", kNoDirCheck);
  REQUIRE(c.plugins.size() == 3);
  CHECK(*c.plugins[0].budget.time_us == 250.5);
  CHECK(c.plugins[0].budget.cycles == 3);
  CHECK(*c.plugins[1].budget.time_us == 0.0);  // no budget
  CHECK(c.plugins[1].budget.cycles == 20);     // the stated default
  CHECK(c.plugins[1].on_rt_allocation == cfg::AllocationPolicy::count);
  CHECK_FALSE(c.plugins[2].budget.time_us.has_value());  // the loop's period
  CHECK_FALSE(c.plugins[2].on_rt_allocation.has_value());
  CHECK(c.safety.on_rt_allocation == cfg::AllocationPolicy::deactivate);
  CHECK(cfg::load_daemon_config_from_string(HEAD, "/etc/crease/fw.yaml", kNoDirCheck).safety.on_rt_allocation ==
        cfg::AllocationPolicy::count);

  const std::string plugin = head + "plugins:\n  - {name: a, library: x, loop: control, order: 1, ";
  CHECK(error_of(plugin + "budget: {time_us: -5}}\n") ==
        "/etc/crease/bad.yaml:7:70: plugins[0].budget.time_us: must be in [0, 1e+07], got -5");
  CHECK(error_of(plugin + "budget: {cycles: 0}}\n") ==
        "/etc/crease/bad.yaml:7:69: plugins[0].budget.cycles: must be in [1, 1000000], got 0");
  CHECK(error_of(plugin + "budget: {tim_us: 5}}\n") ==
        "/etc/crease/bad.yaml:7:61: plugins[0].budget.tim_us: unknown key 'tim_us' (did you mean 'time_us'?)");
  CHECK(error_of(plugin + "on_rt_allocation: abort}\n") ==
        "/etc/crease/bad.yaml:7:70: plugins[0].on_rt_allocation: expected 'count' or 'deactivate', got 'abort'");
  CHECK(error_of(head + "safety: {on_rt_allocation: 1}\n") ==
        "/etc/crease/bad.yaml:6:28: safety.on_rt_allocation: expected 'count' or 'deactivate', got '1'");
}
