// crease-bench flood [--seconds N] [--rate R] [--clients C]: the 1 kHz loop's wake-up latency
// with and without a flood of control requests (default 10,000 per second for 10 s, from 4
// clients), measured in the same run on the same daemon.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "bench_registry.h"
#include "bench_util.h"
#include "core/config/daemon_config.h"
#include "core/control/control_client.h"
#include "core/daemon/daemon.h"
#include "rt/histogram.h"

namespace {
using Snapshot = crease::rt::HistogramSnapshot;

// The samples recorded between two snapshots of one histogram.
Snapshot difference(const Snapshot& later, const Snapshot& earlier) {
  Snapshot d = later;
  d.count = 0;
  d.max_ns = 0;
  for (std::size_t b = 0; b < d.counts.size(); ++b) {
    d.counts[b] = later.counts[b] - earlier.counts[b];
    d.count += d.counts[b];
    if (d.counts[b] > 0) d.max_ns = crease::rt::Histogram::bucket_upper(b);
  }
  d.max_ns = std::min(d.max_ns, later.max_ns);
  return d;
}

int run(int argc, char** argv) {
  const double seconds = crease::bench::arg_double(argc, argv, "--seconds", 10);
  const double rate = crease::bench::arg_double(argc, argv, "--rate", 10000);
  const int clients = static_cast<int>(crease::bench::arg_double(argc, argv, "--clients", 4));
  const int priority = static_cast<int>(crease::bench::arg_double(argc, argv, "--priority", 80));

  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("crease-flood-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string sock = (dir / "creased.sock").string();
  {
    std::ofstream cfg(dir / "flood.yaml");
    cfg << "plugin_dirs: [" << CREASE_PLUGIN_DIR << "]\n"
        << "loops:\n  - {name: control, rate_hz: 1000, priority: " << priority << ", cpu: 1}\n"
        << "plugins:\n  - {name: counter, library: crease_test_counter_v1, loop: control, order: 1}\n"
        << "  - {name: noop, library: crease_test_noop, loop: control, order: 2, ports: {out: noop_out}}\n";
  }
  crease::daemon::Options opts;
  opts.socket = sock;
  opts.progress = false;
  opts.duration_s = 2 * seconds + 5;
  crease::daemon::Daemon daemon(crease::config::load_daemon_config((dir / "flood.yaml").string()), opts);
  std::thread runner([&] { daemon.run(); });
  for (int i = 0; i < 200 && !std::filesystem::exists(sock); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  const crease::Loop* loop = daemon.host().loops()[0];
  const Snapshot s0 = loop->timing().wakeup_latency.snapshot();
  std::printf("flood: phase 1: 1 kHz loop, no requests, %.0f s\n", seconds);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const Snapshot s1 = loop->timing().wakeup_latency.snapshot();

  std::printf("flood: phase 2: %.0f requests/s from %d clients, %.0f s\n", rate, clients, seconds);
  std::atomic<std::uint64_t> sent{0}, ok{0}, errors{0};
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration<double>(seconds);
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      crease::control::ControlClient client(sock);
      const double per_client = rate / clients;
      const nlohmann::json reqs[] = {{{"cmd", "status"}},
                                     {{"cmd", "param"}, {"action", "get"}, {"instance", "counter"}, {"key", "increment"}},
                                     {{"cmd", "param"}, {"action", "set"}, {"instance", "counter"}, {"key", "increment"}, {"value", 1}},
                                     {{"cmd", "loops"}}};
      for (std::uint64_t n = 0;; ++n) {
        const auto due = start + std::chrono::duration<double>(double(n) / per_client);
        if (due >= end) break;
        std::this_thread::sleep_until(due);
        try {
          const auto r = client.request(reqs[(n + c) % 4]);
          sent++;
          (r.value("ok", false) ? ok : errors)++;
        } catch (const std::exception&) {
          sent++;
          errors++;
        }
      }
    });
  }
  for (auto& t : threads) t.join();
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const Snapshot s2 = loop->timing().wakeup_latency.snapshot();
  daemon.request_stop();
  runner.join();
  std::filesystem::remove_all(dir);

  const Snapshot quiet = difference(s1, s0);
  const Snapshot flood = difference(s2, s1);
  auto row = [](const char* name, const Snapshot& s) {
    std::printf("  %-28s %9.1f %9.1f %9.1f %9.1f %9llu\n", name, s.percentile(50) / 1e3, s.percentile(99) / 1e3,
                s.percentile(99.9) / 1e3, double(s.max_ns) / 1e3, (unsigned long long)s.count);
  };
  std::printf("\n  wake-up latency (us)         %9s %9s %9s %9s %9s\n", "p50", "p99", "p99.9", "max", "cycles");
  row("no requests", quiet);
  row("with the flood", flood);
  const double p99_ratio = double(flood.percentile(99)) / std::max<double>(1000.0, double(quiet.percentile(99)));
  const double p999_ratio = double(flood.percentile(99.9)) / std::max<double>(1000.0, double(quiet.percentile(99.9)));
  std::printf("  requests: %llu in %.1f s (%.0f/s), failed: %llu\n", (unsigned long long)sent.load(), elapsed,
              double(sent.load()) / elapsed, (unsigned long long)errors.load());
  std::printf("flood: p99_ratio=%.2f p999_ratio=%.2f requests=%llu errors=%llu\n", p99_ratio, p999_ratio,
              (unsigned long long)sent.load(), (unsigned long long)errors.load());
  return errors.load() == 0 ? 0 : 1;
}
}  // namespace

CREASE_BENCH(flood, "1 kHz loop latency with and without 10,000 control requests per second", run);
