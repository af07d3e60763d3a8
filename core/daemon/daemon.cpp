#include "core/daemon/daemon.h"

#include <signal.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "core/control/protocol.h"
#include "core/control/sd_notify.h"
#include "core/control/socket_path.h"
#include "core/daemon/commands/commands.h"
#include "core/daemon/console.h"
#include "core/daemon/startup_stop.h"
#include "core/errors.h"
#include "rt/clock.h"
#include "rt/rt_setup.h"
#include "rt/thread_placement.h"

namespace fs = std::filesystem;

namespace crease::daemon {
namespace {

using control::RequestError;

// One line per real-time setting: applied, or not and why.
void log_step(const rt::SetupStep& step) {
  if (step.applied) spdlog::info("{}: applied", step.what);
  else spdlog::warn("{}: not applied: {}", step.what, step.why);
}

InstanceSpec to_spec(const config::PluginConfig& p, const config::SafetyConfig& safety, const std::string& file,
                     std::size_t index) {
  InstanceSpec s;
  s.name = p.name;
  s.library = p.library;
  s.loop = p.loop;
  s.order = p.order;
  s.enabled = p.enabled;
  s.ports = p.ports;
  s.params = Params(p.params, file, "plugins[" + std::to_string(index) + "].params");
  if (p.budget.time_us) s.budget_ns = static_cast<std::int64_t>(std::llround(*p.budget.time_us * 1000.0));
  s.budget_cycles = static_cast<std::uint32_t>(p.budget.cycles);
  s.deactivate_on_allocation = p.on_rt_allocation.value_or(safety.on_rt_allocation) == config::AllocationPolicy::deactivate;
  return s;
}

// daemon.non_rt_cpus, or every CPU of the process that no loop is pinned to.
std::vector<int> non_rt_cpus_of(const config::DaemonConfig& c) {
  if (c.daemon.non_rt_cpus) return *c.daemon.non_rt_cpus;
  std::vector<int> out;
  for (int cpu : rt::process_cpus()) {
    bool pinned = false;
    for (const auto& l : c.loops) pinned |= l.cpu == cpu;
    if (!pinned) out.push_back(cpu);
  }
  return out;
}

}  // namespace

Daemon::Daemon(config::DaemonConfig config, Options options) : config_(std::move(config)), options_(std::move(options)) {
  // First, before anything makes a thread (a plugin's configure may): the non-RT threads' CPUs.
  // This thread moves there, so every thread made from here on starts there; a loop pins
  // itself to its own CPU.
  const std::vector<int> non_rt = non_rt_cpus_of(config_);
  non_rt_step_ = rt::set_non_rt_cpus(non_rt);
  if (non_rt_step_.applied) {
    facts_.non_rt_cpus = rt::format_cpu_list(non_rt);
    for (const auto& l : config_.loops) {
      if (std::find(non_rt.begin(), non_rt.end(), l.cpu) != non_rt.end()) {
        non_rt_step_.what += "; shared with loop '" + l.name + "'";
      }
    }
  }
  facts_.config_file = config_.file;
  std::vector<fs::path> dirs;
  for (const auto& d : options_.plugin_dirs.empty() ? config_.plugin_dirs : options_.plugin_dirs) dirs.emplace_back(d);
  host_ = std::make_unique<PluginHost>(dirs);
  host_->set_event_sink([](const HostEvent& e) {
    if (e.type == HostEvent::Type::fault) return;  // the host logs faults itself
    if (e.type == HostEvent::Type::device_fault) {
      spdlog::warn("{} '{}' in loop '{}': {}", to_string(e.type), e.instance, e.loop, e.detail);
      return;
    }
    spdlog::info("{} '{}' in loop '{}'{}{}", to_string(e.type), e.instance, e.loop, e.detail.empty() ? "" : ": ", e.detail);
  });
  for (const auto& l : config_.loops) host_->add_loop({l.name, l.rate_hz, l.priority, l.cpu, l.phase_ns});
  for (std::size_t i = 0; i < config_.plugins.size(); ++i) {
    const auto& p = config_.plugins[i];
    const std::string which = "plugin " + std::to_string(i + 1) + " of " + std::to_string(config_.plugins.size()) +
                              " ('" + p.name + "')";
    check_startup_stop("before " + which, which + ": its load, configure and activate");
    try {
      host_->add_instance(to_spec(p, config_.safety, config_.file, i));
    } catch (const std::exception& e) {
      // Prefix with where the instance is declared, unless the message already points there.
      const std::string what = e.what();
      const std::string at = p.loc.str() + ": plugins[" + std::to_string(i) + "] '" + p.name + "': ";
      if (what.rfind(config_.file, 0) == 0) throw ConfigError(what);
      throw ConfigError(at + what);
    }
  }
}

Daemon::~Daemon() {
  if (server_) server_->stop();
  host_.reset();
}

int Daemon::run() {
  const auto& d = config_.daemon;
  check_startup_stop("after loading every plugin", d.lock_memory ? "locking and prefaulting memory" : "starting the control socket");
  if (d.lock_memory) {
    const auto step = rt::lock_memory(static_cast<std::size_t>(d.prefault_heap_mb) << 20);
    facts_.mlockall_applied = step.applied;
    log_step(step);
    check_startup_stop("after locking and prefaulting memory", "starting the control socket");
  }
  log_step(non_rt_step_);
  rt::DmaLatencyRequest dma;
  if (d.cpu_dma_latency_us) {
    const auto step = dma.request(*d.cpu_dma_latency_us);
    log_step(step);
  }

  control::ServerOptions so;
  so.socket_path = options_.socket ? *options_.socket : d.socket ? *d.socket : control::default_socket_path();
  so.socket_group = d.socket_group;
  so.idle_timeout = std::chrono::milliseconds(std::llround(d.control.idle_timeout_s * 1e3));
  so.max_requests_per_s = d.control.max_requests_per_s;
  so.max_clients = static_cast<std::size_t>(d.control.max_clients);
  server_ = std::make_unique<control::ControlServer>(so, *this);
  server_->start();  // before the loops: its threads' creation is done when they take deadlines
  // The start-up watch ends here: a signal from now on is the loop below's to take.
  finish_startup("before starting the loops");

  facts_.start_ns = rt::now_ns();
  facts_.sched_fifo_applied = true;
  facts_.affinity_applied = true;
  bool any_fifo = false, any_cpu = false;
  for (const auto& step : host_->start()) {
    const bool fifo = step.kind == rt::SetupStep::Kind::sched_fifo;
    const bool cpu = step.kind == rt::SetupStep::Kind::affinity;
    any_fifo |= fifo;
    any_cpu |= cpu;
    if (fifo && !step.applied) facts_.sched_fifo_applied = false;
    if (cpu && !step.applied) facts_.affinity_applied = false;
    log_step(step);
  }
  figures_ = std::make_unique<FigureWatch>(host_->ports());
  facts_.threads = thread_placements();  // the loops and the plugins' workers run by now
  facts_.sched_fifo_applied &= any_fifo;
  facts_.affinity_applied &= any_cpu;
  spdlog::info("creased running: {} loops, {} plugins, control socket {}", config_.loops.size(), config_.plugins.size(),
               server_->socket_path());
  control::notify_ready("running " + config_.file);
  // systemd's watchdog wants a ping at least every half interval.
  const auto watchdog = control::watchdog_interval();
  const std::int64_t ping_ns = watchdog ? std::chrono::nanoseconds(*watchdog).count() / 2 : 0;
  std::int64_t next_ping = rt::now_ns();

  const std::optional<double> duration = options_.duration_s ? options_.duration_s : d.duration_s;
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  const timespec tick{0, 50'000'000};
  double next_progress = 1.0;
  std::uint64_t faults_seen = 0, overruns_last = 0;
  while (!stop_.load()) {
    const int sig = sigtimedwait(&signals, nullptr, &tick);
    if (sig == SIGINT || sig == SIGTERM) {
      stop_reason_ = sig == SIGINT ? "SIGINT" : "SIGTERM";
      break;
    }
    host_->poll();
    const double t = double(rt::now_ns() - facts_.start_ns) * 1e-9;
    if (config_.safety.on_fault == config::FaultPolicy::stop && host_->fault_count() > faults_seen) {
      stop_reason_ = "a plugin faulted (safety.on_fault: stop)";
      break;
    }
    faults_seen = host_->fault_count();
    if (watchdog && rt::now_ns() >= next_ping) {
      control::notify_watchdog();
      next_ping += ping_ns;
    }
    if (t >= next_progress) {
      std::uint64_t overruns = 0;
      for (const Loop* l : host_->loops()) overruns += l->timing().missed_periods.load();
      if (config_.safety.max_overruns_per_s > 0 && double(overruns - overruns_last) > config_.safety.max_overruns_per_s) {
        stop_reason_ = "overruns above safety.max_overruns_per_s";
        break;
      }
      overruns_last = overruns;
      if (options_.progress) print_progress(t);
      next_progress += 1.0;
    }
    if (duration && t >= *duration) {
      stop_reason_ = "duration reached";
      break;
    }
  }
  control::notify_stopping(stop_reason_);
  spdlog::info("stopping: {}", stop_reason_);
  server_->stop();
  const std::vector<FigureReading> figures = figures_->take();  // before the outputs go safe
  host_->stop();  // drives every output safe, deactivates in reverse order
  host_->poll();
  print_summary(*host_, {double(rt::now_ns() - facts_.start_ns) * 1e-9, stop_reason_, figures});
  const std::optional<std::string> dir = options_.report_dir ? options_.report_dir : config_.daemon.report_dir;
  if (dir) {
    const std::vector<report::FigureSummary> summaries = figure_summaries(figures);  // as the run left them
    write_reports(*host_, facts_, *dir, &summaries);
  }
  return 0;
}

void Daemon::print_progress(double t_s) {
  std::printf("%s\n", progress_line(*host_, t_s, figures_->take()).c_str());
  std::fflush(stdout);
}

nlohmann::json Daemon::handle(const nlohmann::json& req) {
  requests_.fetch_add(1);
  const std::string cmd = req.at("cmd").get<std::string>();
  const CommandHandler handler = find_command(cmd);
  if (handler == nullptr) throw RequestError(control::kErrorUnknownCommand, "unknown command '" + cmd + "'");
  CommandContext ctx{*host_, facts_, server_.get(), [this](const std::string& reason) {
                       stop_reason_ = reason;
                       stop_.store(true);
                     }};
  return handler(req, ctx);
}

}  // namespace crease::daemon
