// creased: the Crease daemon.
//   creased --config FILE [--socket PATH] [--duration SECONDS] [--report-dir DIR]
//           [--log-level LEVEL] [--plugin-dir DIR]... [--no-progress] [--set INSTANCE.KEY=VALUE]...
// Exit status: 0 after a clean stop (also a SIGINT/SIGTERM during start-up: what was built is
// unwound, no loop runs; a stage still under way daemon.startup_stop_grace_s after the signal
// is cut short: startup_stop.h), 2 for a configuration or plugin error (nothing started), 1 for
// any other failure.
#include <signal.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "core/config/daemon_config.h"
#include "core/control/control_server.h"
#include "core/daemon/daemon.h"
#include "core/daemon/startup_stop.h"
#include "core/errors.h"

namespace {

// --record-state / --record-truth: `key` of the configuration's one sheet_score instance.
void record_override(crease::config::DaemonConfig& config, const char* flag, const char* key, const std::string& file) {
  if (file.empty()) return;
  std::string instance;
  for (const auto& p : config.plugins) {
    if (p.library != "sheet_score") continue;
    if (!instance.empty())
      throw crease::ConfigError(std::string(flag) + ": " + config.file + " has several sheet_score instances ('" +
                                instance + "', '" + p.name + "'): use --set INSTANCE." + key + "=FILE");
    instance = p.name;
  }
  if (instance.empty()) throw crease::ConfigError(std::string(flag) + ": " + config.file + " has no sheet_score instance");
  crease::config::override_param(config, instance + "." + key + "=" + file);
}

}  // namespace

int main(int argc, char** argv) {
  // Signals are taken by the main thread with sigtimedwait: block them before any thread exists.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  signal(SIGPIPE, SIG_IGN);

  CLI::App app{"creased: runs Crease loops and plugins as configured"};
  std::string config_file, log_level = "info";
  crease::daemon::Options options;
  double duration = 0;
  std::string socket, report_dir;
  bool no_progress = false;
  app.add_option("--config", config_file, "YAML configuration")->required();
  app.add_option("--socket", socket, "control socket path");
  app.add_option("--duration", duration, "stop after this many seconds")->check(CLI::PositiveNumber);
  app.add_option("--report-dir", report_dir, "write report.{html,json,txt} here at exit");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  app.add_option("--plugin-dir", options.plugin_dirs, "plugin directory (replaces the configuration's)");
  app.add_flag("--no-progress", no_progress, "no progress line every second");
  std::vector<std::string> overrides;
  app.add_option("--set", overrides, "INSTANCE.KEY=VALUE: a plugin parameter instead of the configuration's "
                                     "(repeatable), e.g. --set score.record=state.jsonl");
  std::string record_state, record_truth;
  app.add_option("--record-state", record_state,
                 "FILE: the sheet_score instance records every model frame there (its `record`), for crease-score");
  app.add_option("--record-truth", record_truth,
                 "FILE: the sheet_score instance records the truth there (its `record_truth`), for crease-score");
  CLI11_PARSE(app, argc, argv);
  if (!socket.empty()) options.socket = socket;
  if (duration > 0) options.duration_s = duration;
  if (!report_dir.empty()) options.report_dir = report_dir;
  options.progress = !no_progress;

  spdlog::set_level(spdlog::level::from_str(log_level));
  // Under systemd, journald adds time and unit: keep lines short.
  if (std::getenv("JOURNAL_STREAM") != nullptr) spdlog::set_pattern("[%l] %v");

  // From here until the loops start, a thread of its own takes SIGINT/SIGTERM: honoured at the
  // next stage, or within the grace if a stage takes longer (startup_stop.h).
  std::optional<crease::daemon::StartupWatch> watch;
  try {
    watch.emplace();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "creased: %s\n", e.what());
    return 1;
  }
  std::unique_ptr<crease::daemon::Daemon> daemon;
  try {
    watch->enter("reading the configuration");
    crease::config::DaemonConfig config = crease::config::load_daemon_config(config_file);
    for (const std::string& o : overrides) crease::config::override_param(config, o);
    record_override(config, "--record-state", "record", record_state);
    record_override(config, "--record-truth", "record_truth", record_truth);
    watch->set_grace(config.daemon.startup_stop_grace_s);
    crease::daemon::check_startup_stop("after reading the configuration", "placing the threads and loading the plugins");
    daemon = std::make_unique<crease::daemon::Daemon>(std::move(config), options);
  } catch (const crease::daemon::StartupStopped& e) {  // what was built is unwound by now
    std::printf("creased: %s; no loop ran\n", e.what());
    return 0;
  } catch (const crease::Error& e) {  // ConfigError, LoadError, PortError
    std::fprintf(stderr, "creased: %s\n", e.what());
    return 2;
  }
  try {
    return daemon->run();
  } catch (const crease::daemon::StartupStopped& e) {
    daemon.reset();  // plugins deactivated and unloaded, the socket removed
    std::printf("creased: %s; no loop ran\n", e.what());
    return 0;
  } catch (const crease::control::ControlError& e) {
    std::fprintf(stderr, "creased: control socket: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "creased: %s\n", e.what());
    return 1;
  }
}
