#include "core/daemon/daemon.h"

#include <signal.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <spdlog/spdlog.h>

#include "core/control/protocol.h"
#include "core/control/sd_notify.h"
#include "core/control/socket_path.h"
#include "core/errors.h"
#include "core/report/render.h"
#include "rt/clock.h"
#include "rt/rt_setup.h"

namespace fs = std::filesystem;

namespace crease::daemon {
namespace {

using control::RequestError;

double us(std::uint64_t ns) { return double(ns) / 1000.0; }

// One line per real-time setting: applied, or not and why.
void log_step(const rt::SetupStep& step) {
  if (step.applied) spdlog::info("{}: applied", step.what);
  else spdlog::warn("{}: not applied: {}", step.what, step.why);
}

InstanceSpec to_spec(const config::PluginConfig& p, const std::string& file, std::size_t index) {
  InstanceSpec s;
  s.name = p.name;
  s.library = p.library;
  s.loop = p.loop;
  s.order = p.order;
  s.enabled = p.enabled;
  s.ports = p.ports;
  s.params = Params(p.params, file, "plugins[" + std::to_string(index) + "].params");
  return s;
}

}  // namespace

Daemon::Daemon(config::DaemonConfig config, Options options) : config_(std::move(config)), options_(std::move(options)) {
  std::vector<fs::path> dirs;
  for (const auto& d : options_.plugin_dirs.empty() ? config_.plugin_dirs : options_.plugin_dirs) dirs.emplace_back(d);
  host_ = std::make_unique<PluginHost>(dirs);
  host_->set_event_sink([](const HostEvent& e) {
    if (e.type == HostEvent::Type::fault) return;  // the host logs faults itself
    spdlog::info("{} '{}' in loop '{}'{}{}", to_string(e.type), e.instance, e.loop, e.detail.empty() ? "" : ": ", e.detail);
  });
  for (const auto& l : config_.loops) host_->add_loop({l.name, l.rate_hz, l.priority, l.cpu});
  for (std::size_t i = 0; i < config_.plugins.size(); ++i) {
    const auto& p = config_.plugins[i];
    try {
      host_->add_instance(to_spec(p, config_.file, i));
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
  if (d.lock_memory) {
    const auto step = rt::lock_memory(static_cast<std::size_t>(d.prefault_heap_mb) << 20);
    facts_.mlockall_applied = step.applied;
    log_step(step);
  }
  rt::DmaLatencyRequest dma;
  if (d.cpu_dma_latency_us) {
    const auto step = dma.request(*d.cpu_dma_latency_us);
    log_step(step);
  }

  control::ServerOptions so;
  so.socket_path = options_.socket ? *options_.socket : d.socket ? *d.socket : control::default_socket_path();
  so.socket_group = d.socket_group;
  server_ = std::make_unique<control::ControlServer>(so, *this);
  server_->start();  // before the loops: its threads' creation is done when they take deadlines

  facts_.config_file = config_.file;
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
  observer_ = std::make_unique<StateObserver>(host_->ports(), options_.record_state, facts_.start_ns);
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
  observer_->stop();  // takes the last model frame before outputs go safe
  tracking_ = observer_->summary();
  host_->stop();  // drives every output safe, deactivates in reverse order
  host_->poll();
  print_summary();
  write_reports();
  return 0;
}

void Daemon::print_progress(double t_s) {
  std::string line = "[" + std::to_string(static_cast<int>(t_s)) + " s]";
  for (const Loop* l : host_->loops()) {
    const auto snap = l->timing().wakeup_latency.snapshot();
    char buf[200];
    std::snprintf(buf, sizeof(buf), " %s: %llu cycles, wake p99 %.0f us, overruns %llu;", l->spec().name.c_str(),
                  (unsigned long long)l->timing().cycles.load(), us(snap.percentile(99)),
                  (unsigned long long)l->timing().missed_periods.load());
    line += buf;
  }
  line += " faults " + std::to_string(host_->fault_count());
  if (observer_) {
    const TrackingSummary t = observer_->take_window();
    tracking_ = t;
    if (t.scored) {
      char buf[160];
      std::snprintf(buf, sizeof(buf), "; tracking error vs truth: %.2f mm (this second), %.2f mm (mean so far)",
                    t.window_mean_mm, t.mean_mm);
      line += buf;
    }
  }
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

void Daemon::print_summary() const {
  const double t = double(rt::now_ns() - facts_.start_ns) * 1e-9;
  std::printf("\ncreased: ran %.1f s (%s)\n", t, stop_reason_.c_str());
  std::printf("  %-14s %8s %10s %10s %10s %10s %10s %9s\n", "loop/plugin", "rate Hz", "cycles", "wake p50", "wake p99",
              "wake max", "exec p99", "overruns");
  const auto instances = host_->instances();
  for (const Loop* l : host_->loops()) {
    const auto w = l->timing().wakeup_latency.snapshot();
    const auto e = l->timing().execution.snapshot();
    std::printf("  %-14s %8.0f %10llu %8.1fus %8.1fus %8.1fus %8.1fus %9llu\n", l->spec().name.c_str(), l->spec().rate_hz,
                (unsigned long long)l->timing().cycles.load(), us(w.percentile(50)), us(w.percentile(99)), us(w.max_ns),
                us(e.percentile(99)), (unsigned long long)l->timing().missed_periods.load());
    for (const InstanceInfo& i : instances) {
      if (i.loop != l->spec().name) continue;
      const auto x = i.stats->execution.snapshot();
      std::printf("    %-12s %8s %10llu %10s %10s %8.1fus %8.1fus  %s, faults %llu, swaps %llu\n", i.name.c_str(), "",
                  (unsigned long long)i.stats->updates.load(), "", "", us(x.max_ns), us(x.percentile(99)),
                  to_string(i.state), (unsigned long long)i.stats->faults.load(), (unsigned long long)i.stats->swaps.load());
    }
  }
  std::printf("  faults: %llu\n", (unsigned long long)host_->fault_count());
  if (tracking_.scored) {
    std::printf("  tracking error of sheet_state vs sheet_truth: mean %.2f mm over %llu model frames, last %.2f mm, "
                "worst %.2f mm\n",
                tracking_.mean_mm, (unsigned long long)tracking_.frames, tracking_.last_mm, tracking_.max_mm);
  }
  if (!options_.record_state.empty()) {
    std::printf("  recorded %llu model frames to %s (%llu not seen)\n", (unsigned long long)tracking_.recorded,
                options_.record_state.c_str(), (unsigned long long)tracking_.missed);
  }
  std::fflush(stdout);
}

void Daemon::write_reports() const {
  const std::optional<std::string> dir = options_.report_dir ? options_.report_dir : config_.daemon.report_dir;
  if (!dir) return;
  std::error_code ec;
  fs::create_directories(*dir, ec);
  const report::TimingReport r = build_report(*host_, facts_);
  for (const auto& [format, name] : {std::pair{report::Format::html, "report.html"}, std::pair{report::Format::json, "report.json"},
                                     std::pair{report::Format::text, "report.txt"}}) {
    const fs::path p = fs::path(*dir) / name;
    std::ofstream f(p);
    f << report::render(r, format);
    if (!f) spdlog::error("cannot write report {}", p.string());
  }
  std::printf("  reports: %s/report.{html,json,txt}\n", fs::absolute(*dir).string().c_str());
  std::fflush(stdout);
}

nlohmann::json Daemon::status() const {
  return {{"state", "running"},
          {"config", config_.file},
          {"uptime_s", double(rt::now_ns() - facts_.start_ns) * 1e-9},
          {"loops", host_->loops().size()},
          {"plugins", host_->instances().size()},
          {"faults", host_->fault_count()},
          {"sched_fifo", facts_.sched_fifo_applied},
          {"mlockall", facts_.mlockall_applied}};
}

nlohmann::json Daemon::loops_json() const {
  nlohmann::json out = nlohmann::json::array();
  for (const Loop* l : host_->loops()) {
    const auto w = l->timing().wakeup_latency.snapshot();
    const auto e = l->timing().execution.snapshot();
    out.push_back({{"name", l->spec().name},
                   {"rate_hz", l->spec().rate_hz},
                   {"priority", l->spec().priority},
                   {"cpu", l->spec().cpu},
                   {"sched_fifo", l->fifo_applied()},
                   {"cycles", l->timing().cycles.load()},
                   {"overruns", l->timing().missed_periods.load()},
                   {"missed_deadlines", l->timing().overruns.load()},
                   {"wakeup_p50_us", us(w.percentile(50))},
                   {"wakeup_p99_us", us(w.percentile(99))},
                   {"wakeup_max_us", us(w.max_ns)},
                   {"exec_p99_us", us(e.percentile(99))}});
  }
  return out;
}

nlohmann::json Daemon::plugins_json() const {
  nlohmann::json out = nlohmann::json::array();
  for (const InstanceInfo& i : host_->instances()) {
    nlohmann::json tunables = nlohmann::json::object();
    for (const Tunable& t : i.tunables) tunables[t.key] = {{"value", t.value}, {"min", t.lo}, {"max", t.hi}};
    const auto x = i.stats->execution.snapshot();
    out.push_back({{"name", i.name},
                   {"loop", i.loop},
                   {"order", i.order},
                   {"plugin", i.plugin},
                   {"version", i.version},
                   {"library", i.library},
                   {"state", to_string(i.state)},
                   {"last_fault", to_string(i.last_fault)},
                   {"updates", i.stats->updates.load()},
                   {"degraded", i.stats->degraded.load()},
                   {"faults", i.stats->faults.load()},
                   {"swaps", i.stats->swaps.load()},
                   {"exec_p99_us", us(x.percentile(99))},
                   {"tunables", tunables}});
  }
  return out;
}

nlohmann::json Daemon::ports_json() const {
  nlohmann::json out = nlohmann::json::array();
  for (const PortInfo& p : host_->ports().list()) {
    nlohmann::json j = {{"name", p.name},
                        {"kind", p.kind == PortKind::latest ? "latest" : "queue"},
                        {"type", p.type_name},
                        {"version", p.type_version},
                        {"size", p.size},
                        {"writer", p.writer},
                        {"readers", p.readers}};
    if (p.kind == PortKind::latest) j["writes"] = p.sequence;
    else j.update({{"capacity", p.capacity}, {"pushed", p.pushed}, {"dropped", p.dropped}});
    out.push_back(std::move(j));
  }
  return out;
}

nlohmann::json Daemon::stats_json() const {
  return {{"control", server_ ? server_->counters().to_json() : nlohmann::json()},
          {"faults", host_->fault_count()},
          {"loops", loops_json()}};
}

nlohmann::json Daemon::handle(const nlohmann::json& req) {
  requests_.fetch_add(1);
  const std::string cmd = req.at("cmd").get<std::string>();
  auto guarded = [&](auto&& fn) -> nlohmann::json {
    try {
      return fn();
    } catch (const RequestError&) {
      throw;
    } catch (const std::exception& e) {
      throw RequestError(control::kErrorFailed, e.what());
    }
  };
  if (cmd == "status") return status();
  if (cmd == "loops") return loops_json();
  if (cmd == "plugins") return plugins_json();
  if (cmd == "ports") return ports_json();
  if (cmd == "stats") return stats_json();
  if (cmd == "stop") {
    stop_reason_ = "creasectl stop";
    stop_.store(true);
    return {{"stopping", true}};
  }
  if (cmd == "report") {
    const std::string f = control::require_string(req, "format");
    report::Format format;
    if (f == "html") format = report::Format::html;
    else if (f == "json") format = report::Format::json;
    else if (f == "text") format = report::Format::text;
    else throw RequestError(control::kErrorBadArgument, "report: format must be html, json or text, not '" + f + "'");
    return {{"format", f}, {"content", report::render(build_report(*host_, facts_), format)}};
  }
  const std::string instance = control::require_string(req, "instance");
  auto params_of = [&](const char* key) -> std::optional<Params> {
    if (!req.contains(key)) return std::nullopt;
    if (!req[key].is_object()) throw RequestError(control::kErrorBadArgument, cmd + ": '" + key + "' must be an object");
    return Params(YAML::Load(req[key].dump()), "request", instance + ".params");
  };
  if (cmd == "load") {
    InstanceSpec s;
    s.name = instance;
    s.library = control::require_string(req, "library");
    s.loop = control::require_string(req, "loop");
    s.order = static_cast<int>(control::require_int(req, "order"));
    if (auto p = params_of("params")) s.params = *p;
    if (req.contains("ports") && req["ports"].is_object()) {
      for (const auto& [k, v] : req["ports"].items()) {
        if (!v.is_string()) throw RequestError(control::kErrorBadArgument, "load: ports values must be strings");
        s.ports[k] = v.get<std::string>();
      }
    }
    return guarded([&] {
      host_->add_instance(s);
      return nlohmann::json{{"loaded", instance}};
    });
  }
  if (cmd == "unload") return guarded([&] { host_->unload(instance); return nlohmann::json{{"unloaded", instance}}; });
  if (cmd == "activate") return guarded([&] { host_->activate(instance); return nlohmann::json{{"activated", instance}}; });
  if (cmd == "deactivate") {
    return guarded([&] { host_->deactivate(instance); return nlohmann::json{{"deactivated", instance}}; });
  }
  if (cmd == "swap") {
    const std::string library = control::require_string(req, "library");
    const auto params = params_of("params");
    return guarded([&] {
      host_->swap(instance, library, params);
      return nlohmann::json{{"swapped", instance}, {"library", library}};
    });
  }
  if (cmd == "param") {
    const std::string action = control::require_string(req, "action");
    const std::string key = control::require_string(req, "key");
    if (action == "get") {
      const auto v = host_->get_param(instance, key);
      if (!v) throw RequestError(control::kErrorFailed, "instance '" + instance + "' has no tunable parameter '" + key + "'");
      return {{"instance", instance}, {"key", key}, {"value", *v}};
    }
    if (action == "set") {
      const auto& value = control::require_arg(req, "value");
      double v = 0;
      if (value.is_number()) {
        v = value.get<double>();
      } else if (value.is_string()) {
        try {
          std::size_t used = 0;
          v = std::stod(value.get<std::string>(), &used);
          if (used != value.get<std::string>().size()) throw std::invalid_argument("trailing");
        } catch (const std::exception&) {
          throw RequestError(control::kErrorBadArgument, "param set: value must be a number");
        }
      } else {
        throw RequestError(control::kErrorBadArgument, "param set: value must be a number");
      }
      const std::string why = host_->set_param(instance, key, v);
      if (!why.empty()) throw RequestError(control::kErrorFailed, why);
      return {{"instance", instance}, {"key", key}, {"value", v}, {"applies", "at the next cycle boundary"}};
    }
    throw RequestError(control::kErrorBadArgument, "param: action must be get or set, not '" + action + "'");
  }
  throw RequestError(control::kErrorUnknownCommand, "unknown command '" + cmd + "'");
}

}  // namespace crease::daemon
