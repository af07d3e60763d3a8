// creased's body: builds the plugin host from a validated configuration, runs it until told
// to stop (signals, `stop`, duration, safety policy), dispatches control requests to the
// command handlers (commands/), and at the end prints the summary (console.h) and writes the
// reports (report_builder.h).
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/config/daemon_config.h"
#include "core/control/control_server.h"
#include "core/daemon/report_builder.h"
#include "core/daemon/figures.h"
#include "core/plugin_host.h"
#include "rt/rt_setup.h"

namespace crease::daemon {

struct Options {
  std::optional<std::string> socket;      // overrides the configuration
  std::optional<double> duration_s;       // overrides the configuration
  std::optional<std::string> report_dir;  // overrides the configuration
  std::vector<std::string> plugin_dirs;   // when given, replace the configuration's
  bool progress = true;                   // a line per second on stdout
};

class Daemon final : public control::RequestHandler {
 public:
  // Builds everything (loads, configures and activates every plugin) but starts nothing.
  // Throws ConfigError / LoadError / PortError naming the file, line and key; then nothing runs.
  Daemon(config::DaemonConfig config, Options options);
  ~Daemon() override;

  // Starts the loops and the control server; returns when stopped (signal, `stop`, duration,
  // safety policy). Drives outputs safe, deactivates in reverse order, writes the reports.
  // Returns the exit status (0). A SIGINT/SIGTERM before the loops start throws
  // StartupStopped (startup_stop.h), as does one during construction, between plugins; with a
  // StartupWatch in the process, a stage still under way past its grace ends the process.
  int run();
  void request_stop() noexcept { stop_.store(true); }

  nlohmann::json handle(const nlohmann::json& request) override;

  [[nodiscard]] PluginHost& host() noexcept { return *host_; }

 private:
  void print_progress(double t_s);

  config::DaemonConfig config_;
  Options options_;
  std::unique_ptr<PluginHost> host_;
  std::unique_ptr<control::ControlServer> server_;
  std::unique_ptr<FigureWatch> figures_;     // the plugins' figures for progress and summary
  RunFacts facts_;
  rt::SetupStep non_rt_step_;                // where the non-RT threads were placed
  std::atomic<bool> stop_{false};
  std::string stop_reason_ = "stopped";
  std::atomic<std::uint64_t> requests_{0};
};

}  // namespace crease::daemon
