// crease-bench flood [--seconds N] [--turn S] [--rate R] [--clients C] [--aa]: the 1 kHz loop's
// wake-up latency with and without a flood of control requests (default 10,000 per second from 4
// clients), measured on the same daemon in interleaved turns of S seconds (default 2): quiet,
// flood, quiet, flood, ... for N seconds of each side (default 20 s each, 40 s in all), so a
// neighbour's load that comes and goes falls on both sides alike. p99 of 20,000 cycles a side
// moves by a few per cent between runs on a quiet machine.
// --aa: the same turns with no requests on either side (no client connects): the ratio the
// machine's own noise gives, against which a flood's ratio can be read.
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
  d.sum_ns = later.sum_ns - earlier.sum_ns;
  d.overflow = later.overflow - earlier.overflow;
  for (std::size_t b = 0; b < d.counts.size(); ++b) {
    d.counts[b] = later.counts[b] - earlier.counts[b];
    d.count += d.counts[b];
    if (d.counts[b] > 0) d.max_ns = crease::rt::Histogram::bucket_upper(b);
  }
  d.max_ns = std::min(d.max_ns, later.max_ns);
  return d;
}

// Adds the samples of D to ACC (an empty ACC takes D's bucket layout).
void accumulate(Snapshot& acc, const Snapshot& d) {
  if (acc.counts.empty()) {
    acc = d;
    return;
  }
  for (std::size_t b = 0; b < acc.counts.size() && b < d.counts.size(); ++b) acc.counts[b] += d.counts[b];
  acc.count += d.count;
  acc.sum_ns += d.sum_ns;
  acc.max_ns = std::max(acc.max_ns, d.max_ns);
  acc.overflow += d.overflow;
}

int run(int argc, char** argv) {
  const double seconds = crease::bench::arg_double(argc, argv, "--seconds", 20);  // of each side
  const double turn_s = crease::bench::arg_double(argc, argv, "--turn", 2);
  const double rate = crease::bench::arg_double(argc, argv, "--rate", 10000);
  const int clients = static_cast<int>(crease::bench::arg_double(argc, argv, "--clients", 4));
  const int priority = static_cast<int>(crease::bench::arg_double(argc, argv, "--priority", 80));
  const bool aa = crease::bench::has_flag(argc, argv, "--aa");

  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("crease-flood-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string sock = (dir / "creased.sock").string();
  {
    std::ofstream cfg(dir / "flood.yaml");
    // The daemon's real-time setup as on the robot (config/robot.yaml): memory locked, the CPUs
    // kept out of their deep idle states (cpu_dma_latency 0), for both sides of the comparison.
    cfg << "plugin_dirs: [" << CREASE_PLUGIN_DIR << "]\n"
        << "daemon: {lock_memory: true, prefault_heap_mb: 64, cpu_dma_latency_us: 0}\n"
        << "loops:\n  - {name: control, rate_hz: 1000, priority: " << priority << ", cpu: 1}\n"
        << "plugins:\n  - {name: counter, library: crease_test_counter_v1, loop: control, order: "
           "1}\n"
        << "  - {name: noop, library: crease_test_noop, loop: control, order: 2, ports: {out: "
           "noop_out}}\n";
  }
  crease::daemon::Options opts;
  opts.socket = sock;
  opts.progress = false;
  opts.duration_s = 2 * seconds + 4 * turn_s + 10;
  crease::daemon::Daemon daemon(crease::config::load_daemon_config((dir / "flood.yaml").string()), opts);
  std::thread runner([&] { daemon.run(); });
  for (int i = 0; i < 200 && !std::filesystem::exists(sock); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  const crease::Loop* loop = daemon.host().loops()[0];
  // The clients run throughout and send only during flood turns, paced at their share of RATE.
  std::atomic<bool> flooding{false}, done{false};
  std::atomic<std::uint64_t> sent{0}, errors{0}, busy{0};
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      if (aa) return;  // no client at all
      crease::control::ControlClient client(sock);
      const auto period = std::chrono::duration<double>(double(clients) / rate);
      const nlohmann::json reqs[] = {{{"cmd", "status"}},
                                     {{"cmd", "param"}, {"action", "get"}, {"instance", "counter"}, {"key", "increment"}},
                                     {{"cmd", "param"}, {"action", "set"}, {"instance", "counter"}, {"key", "increment"}, {"value", 1}},
                                     {{"cmd", "loops"}}};
      auto due = std::chrono::steady_clock::now();
      for (std::uint64_t n = 0; !done.load();) {
        if (!flooding.load()) {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
          due = std::chrono::steady_clock::now();
          continue;
        }
        due += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
        std::this_thread::sleep_until(due);
        try {
          const auto r = client.request(reqs[(n++ + c) % 4]);
          sent++;
          if (!r.value("ok", false)) {
            const bool is_busy = r.contains("error") && r["error"].value("code", "") == "busy";
            (is_busy ? busy : errors)++;
          }
        } catch (const std::exception&) {
          sent++;
          errors++;
        }
      }
    });
  }

  const int turns = std::max(1, static_cast<int>(std::lround(seconds / turn_s)));
  if (aa)
    std::printf(
        "flood: %d turns of %.1f s a side, A/A: no requests on either side, %.0f s in all\n", turns,
        turn_s, 2 * turns * turn_s);
  else
    std::printf(
        "flood: %d turns of %.1f s a side (quiet, then %.0f requests/s from %d clients), %.0f s in "
        "all\n",
        turns, turn_s, rate, clients, 2 * turns * turn_s);
  Snapshot quiet, flood;
  double flood_s = 0;
  for (int t = 0; t < 2 * turns; ++t) {
    const bool is_flood = (t % 2) == 1;
    flooding.store(is_flood);
    const Snapshot a = loop->timing().wakeup_latency.snapshot();
    const auto t0 = std::chrono::steady_clock::now();
    std::this_thread::sleep_for(std::chrono::duration<double>(turn_s));
    const Snapshot b = loop->timing().wakeup_latency.snapshot();
    if (is_flood) flood_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    accumulate(is_flood ? flood : quiet, difference(b, a));
  }
  flooding.store(false);
  done.store(true);
  for (auto& t : threads) t.join();
  daemon.request_stop();
  runner.join();
  std::filesystem::remove_all(dir);

  auto row = [](const char* name, const Snapshot& s) {
    std::printf("  %-28s %9.1f %9.1f %9.1f %9.1f %9llu\n", name, s.percentile(50) / 1e3, s.percentile(99) / 1e3,
                s.percentile(99.9) / 1e3, double(s.max_ns) / 1e3, (unsigned long long)s.count);
  };
  std::printf("\n  wake-up latency (us)         %9s %9s %9s %9s %9s\n", "p50", "p99", "p99.9", "max", "cycles");
  row(aa ? "first turns (no requests)" : "no requests", quiet);
  row(aa ? "second turns (no requests)" : "with the flood", flood);
  const double p99_ratio = double(flood.percentile(99)) / std::max<double>(1000.0, double(quiet.percentile(99)));
  const double p999_ratio = double(flood.percentile(99.9)) / std::max<double>(1000.0, double(quiet.percentile(99.9)));
  std::printf("  requests: %llu in %.1f s of flood (%.0f/s), busy: %llu, failed: %llu\n", (unsigned long long)sent.load(),
              flood_s, double(sent.load()) / flood_s, (unsigned long long)busy.load(), (unsigned long long)errors.load());
  std::printf("flood: p99_ratio=%.3f p999_ratio=%.3f requests=%llu errors=%llu\n", p99_ratio,
              p999_ratio, (unsigned long long)sent.load(), (unsigned long long)errors.load());
  return errors.load() == 0 ? 0 : 1;
}
}  // namespace

CREASE_BENCH(flood, "1 kHz loop latency with and without 10,000 control requests per second", run);
