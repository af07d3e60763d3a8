// crease-bench dds [--seconds N] [--turns K] [--priority P] [--cpu C] [--thread-priority T]: the dds_bridge across two
// processes on this machine, over loopback (config/dds/loopback.xml).
//
// A creased child (the peer) runs a 1 kHz loop with crease_test_payload_source, which writes
// hand_state every cycle and keypoints (512 points, keypoints-sized) every 67 cycles (15 Hz),
// each stamped when written, and a bridge publishing both and subscribing hand_command. This
// process runs a 1 kHz loop with a bridge subscribing them, crease_test_payload_probe (reads the
// ports, records how old each new value is) and crease_test_hand_echo (answers hand_command,
// published back by the bridge). Latency, per sample:
//   wire: from the peer's port write to the sample in this bridge's channel, ready for its
//         next update (the port stamp a subscribed bridge writes is that arrival time);
//   port: to the probe's update that read it (wire + the wait for this loop's next cycle).
// Beside it, Cyclone's ddsperf ping-pong with the same sample sizes and rates, in the same run,
// with the same XML and beside the same two 1 kHz loops (no bridge); its one-way figure is the
// round trip / 2. ddsperf prints percentiles per second: its figures (and ours in the
// comparison) are the median over seconds, max the max. And the wake-up latency p99 of this
// process's 1 kHz loop with the bridge (peer bridging) against without (the same peer and loop,
// no bridge on either side, no ddsperf). The three kinds of turn alternate; N seconds each, about
// 3N + 10 s in all.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "bench_registry.h"
#include "bench_util.h"
#include "core/plugin_host.h"
#include "plugins/test_plugins/test_ports.h"
#include "rt/histogram.h"

namespace {
namespace fs = std::filesystem;
using crease::test_plugins::LatencySample;
using Clock = std::chrono::steady_clock;

constexpr int kKeypointsEvery = 67;     // cycles: 15 Hz at 1 kHz
constexpr int kHandStateBytes = 144;    // crease_msgs/msg/HandState as CDR (no padding at the end)
constexpr int kKeypointsBytes = 16408;  // crease_msgs/msg/Keypoints with 512 points as CDR

struct Dist {
  double p50 = 0, p99 = 0, max = 0;  // us
  std::size_t n = 0;
};

Dist dist_of(std::vector<double> v) {
  Dist d;
  d.n = v.size();
  if (v.empty()) return d;
  std::sort(v.begin(), v.end());
  const auto at = [&](double p) {
    const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
    return v[std::clamp<std::size_t>(rank, 1, v.size()) - 1];
  };
  d.p50 = at(50);
  d.p99 = at(99);
  d.max = v.back();
  return d;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Samples bucketed by second of arrival: per-second p50/p99 medians, like ddsperf's output.
Dist per_second(const std::vector<std::pair<std::int64_t, double>>& stamped) {
  std::vector<double> p50s, p99s;
  double max = 0;
  std::vector<double> bucket;
  std::int64_t second = stamped.empty() ? 0 : stamped.front().first / 1'000'000'000;
  const auto flush = [&] {
    if (bucket.size() >= 5) {
      const Dist d = dist_of(bucket);
      p50s.push_back(d.p50);
      p99s.push_back(d.p99);
    }
    bucket.clear();
  };
  for (const auto& [t, us] : stamped) {
    if (t / 1'000'000'000 != second) {
      flush();
      second = t / 1'000'000'000;
    }
    bucket.push_back(us);
    max = std::max(max, us);
  }
  flush();
  return Dist{median(p50s), median(p99s), max, stamped.size()};
}

int g_thread_priority = 0;  // --thread-priority: the bridges' threads

std::string topic(const std::string& name) { return "bench" + std::to_string(::getpid()) + "/" + name; }

// The peer's configuration: the source, and with `bridge` the bridge publishing its ports.
std::string peer_yaml(bool bridge, int domain, const std::string& xml) {
  std::string y = std::string("plugin_dirs: [") + CREASE_PLUGIN_DIR + "]\n" +
                  "daemon: {lock_memory: false}\n"
                  "loops:\n"
                  "  - {name: control, rate_hz: 1000, priority: 70}\n"
                  "plugins:\n"
                  "  - {name: source, library: crease_test_payload_source, loop: control, order: 0,\n"
                  "     params: {keypoints_every: " + std::to_string(kKeypointsEvery) + ", keypoints_count: 512}}\n";
  if (bridge)
    y += "  - name: bridge\n"
         "    library: dds_bridge\n"
         "    loop: control\n"
         "    order: 10\n"
         "    params:\n"
         "      domain: " + std::to_string(domain) + "\n" +
         "      dds_config: " + xml + "\n" +
         "      thread_priority: " + std::to_string(g_thread_priority) + "\n" +
         "      publish: [{port: hand_state, topic: " + topic("hand_state") + "}, {port: keypoints, topic: " +
         topic("keypoints") + "}]\n" +
         "      subscribe: [{topic: " + topic("hand_command") + ", port: hand_command, type: hand_command}]\n";
  return y;
}

struct Peer {
  fs::path dir;
  pid_t pid = -1;
  Peer(const fs::path& d, const std::string& yaml, const std::string& creased) : dir(d) {
    fs::create_directories(dir);
    std::ofstream(dir / "peer.yaml") << yaml;
    const std::string sock = (dir / "creased.sock").string();
    fs::remove(sock);
    std::fflush(nullptr);
    pid = ::fork();
    if (pid == 0) {
      const std::string log = (dir / "creased.log").string();
      std::freopen(log.c_str(), "w", stdout);
      std::freopen(log.c_str(), "a", stderr);
      ::execl(creased.c_str(), "creased", "--config", (dir / "peer.yaml").c_str(), "--socket", sock.c_str(),
              "--report-dir", (dir / "reports").c_str(), "--duration", "600", "--no-progress",
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    for (int i = 0; i < 400 && !fs::exists(sock); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  ~Peer() {
    if (pid > 0) {
      ::kill(pid, SIGTERM);
      ::waitpid(pid, nullptr, 0);
    }
  }
};

crease::InstanceSpec spec(const std::string& name, const std::string& library, const std::string& yaml, int order) {
  crease::InstanceSpec s;
  s.name = name;
  s.library = library;
  s.loop = "control";
  s.order = order;
  s.params = crease::Params(YAML::Load(yaml), "bench", name);
  return s;
}

crease::rt::HistogramSnapshot minus(const crease::rt::HistogramSnapshot& after,
                                    const crease::rt::HistogramSnapshot& before) {
  crease::rt::HistogramSnapshot d = after;
  d.count = 0;
  for (std::size_t b = 0; b < d.counts.size(); ++b) {
    d.counts[b] -= b < before.counts.size() ? before.counts[b] : 0;
    d.count += d.counts[b];
  }
  return d;
}
void accumulate(crease::rt::HistogramSnapshot& into, const crease::rt::HistogramSnapshot& s) {
  if (into.counts.empty()) into.counts.assign(s.counts.size(), 0);
  for (std::size_t b = 0; b < s.counts.size(); ++b) into.counts[b] += s.counts[b];
  into.count += s.count;
  into.max_ns = std::max(into.max_ns, s.max_ns);
}

// Cyclone's ddsperf ping-pong: `size` bytes at `rate_hz` for `seconds` on its own domain, started
// by start() and read by finish(), which adds its per-second lines (round trip / 2: one way).
class DdsPerf {
 public:
  DdsPerf(int size, int rate_hz, int domain, const std::string& xml) : size_(size), rate_(rate_hz), domain_(domain), xml_(xml) {}
  bool start(double seconds) {
    const std::string env = "CYCLONEDDS_URI=file://" + xml_ + " ddsperf -i " + std::to_string(domain_) + " -D ";
    const long dur = std::lround(seconds) + 1;
    if (std::system((env + std::to_string(dur + 2) + " pong >/dev/null 2>&1 &").c_str()) != 0) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ping_ = popen((env + std::to_string(dur) + " ping " + std::to_string(rate_) + "Hz size " + std::to_string(size_) +
                   " 2>&1").c_str(), "r");
    return ping_ != nullptr;
  }
  void finish() {
    if (ping_ == nullptr) return;
    static const std::regex line(
        R"(size (\d+) mean [\d.]+us min [\d.]+us 50% ([\d.]+)us 90% [\d.]+us 99% ([\d.]+)us max ([\d.]+)us cnt (\d+))");
    char buf[1024];
    bool first = true;
    while (std::fgets(buf, sizeof(buf), ping_) != nullptr) {
      std::cmatch m;
      if (!std::regex_search(buf, m, line)) continue;
      if (first) {  // its first second includes discovery
        first = false;
        continue;
      }
      p50s_.push_back(std::stod(m[2].str()) / 2);
      p99s_.push_back(std::stod(m[3].str()) / 2);
      max_ = std::max(max_, std::stod(m[4].str()) / 2);
      n_ += std::stoul(m[5].str());
    }
    pclose(ping_);
    ping_ = nullptr;
  }
  [[nodiscard]] bool ran() const noexcept { return !p99s_.empty(); }
  // Median over its seconds; max the largest.
  [[nodiscard]] Dist one_way() const { return Dist{median(p50s_), median(p99s_), max_, n_}; }

 private:
  int size_, rate_, domain_;
  std::string xml_;
  FILE* ping_ = nullptr;
  std::vector<double> p50s_, p99s_;
  double max_ = 0;
  std::size_t n_ = 0;
};

struct Collected {
  std::vector<std::pair<std::int64_t, double>> wire[2], port[2];  // [kind]: (arrival, us)
};

// One turn: the peer (bridging or not) and this process's loop (with the bridge, probe and echo,
// or a no-op), `seconds` measured after a warm-up. Adds the loop's wake-up latency into `wake`.
// Without the bridge, the `perf` ping-pongs (when given) run during the turn instead: ddsperf
// meets the same two 1 kHz loops the bridge does.
void turn(bool bridge, double seconds, int priority, int cpu, int domain, const std::string& xml,
          const std::string& creased, const fs::path& dir, crease::rt::HistogramSnapshot& wake, Collected& got,
          std::vector<DdsPerf*> perf = {}) {
  Peer peer(dir / (bridge ? "with" : "without"), peer_yaml(bridge, domain, xml), creased);
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, priority, cpu});
  if (bridge) {
    host.add_instance(spec("bridge", "dds_bridge",
                           "{domain: " + std::to_string(domain) + ", dds_config: " + xml +
                               ", thread_priority: " + std::to_string(g_thread_priority) + ", subscribe: [{topic: " +
                               topic("hand_state") + ", port: hand_state, type: hand_state}, {topic: " +
                               topic("keypoints") + ", port: keypoints, type: keypoints}], publish: [{topic: " +
                               topic("hand_command") + ", port: hand_command, type: hand_command}]}",
                           0));
    host.add_instance(spec("probe", "crease_test_payload_probe", "{}", 10));
    host.add_instance(spec("echo", "crease_test_hand_echo", "{}", 20));
  } else {
    host.add_instance(spec("noop", "crease_test_noop", "{}", 0));
  }
  host.start();
  crease::rt::QueueChannel* q = bridge ? host.ports().find_queue("latency") : nullptr;
  LatencySample s;
  const auto drain = [&](bool keep) {
    while (q != nullptr && q->try_pop(&s)) {
      if (!keep) continue;
      const int k = s.kind == LatencySample::keypoints ? 1 : 0;
      got.wire[k].emplace_back(s.arrived_ns, double(s.arrived_ns - s.sent_ns) / 1e3);
      got.port[k].emplace_back(s.arrived_ns, double(s.seen_ns - s.sent_ns) / 1e3);
    }
  };
  // Warm-up: discovery, first samples, caches.
  const auto warm_end = Clock::now() + std::chrono::milliseconds(1500);
  while (Clock::now() < warm_end) {
    drain(false);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (DdsPerf* p : perf) p->start(seconds);
  const crease::rt::HistogramSnapshot before = host.loops()[0]->timing().wakeup_latency.snapshot();
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    drain(true);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  accumulate(wake, minus(host.loops()[0]->timing().wakeup_latency.snapshot(), before));
  drain(true);
  for (DdsPerf* p : perf) p->finish();
  host.stop();
}

void print_row(const char* name, const Dist& d) {
  std::printf("  %-44s %9.1f %9.1f %9.1f %9zu\n", name, d.p50, d.p99, d.max, d.n);
}

int run(int argc, char** argv) {
  const double seconds = crease::bench::arg_double(argc, argv, "--seconds", 10);
  const int turns = std::max(1, static_cast<int>(crease::bench::arg_double(argc, argv, "--turns", 2)));
  const int priority = static_cast<int>(crease::bench::arg_double(argc, argv, "--priority", 80));
  const int cpu = static_cast<int>(crease::bench::arg_double(argc, argv, "--cpu", -1));
  g_thread_priority = static_cast<int>(crease::bench::arg_double(argc, argv, "--thread-priority", 0));
  const int domain = 201 + static_cast<int>(::getpid() % 29);  // apart from the tests' 1..200
  const std::string xml = std::string(CREASE_SOURCE_DIR) + "/config/dds/loopback.xml";
  const std::string creased = (fs::read_symlink("/proc/self/exe").parent_path() / "creased").string();
  const fs::path dir = fs::temp_directory_path() / ("crease-bench-dds-" + std::to_string(::getpid()));
  std::printf("dds: two processes over loopback (%s), domain %d; %d turns of %.1f s each without the bridge, "
              "with it, and with ddsperf instead; this loop 1 kHz at priority %d, the bridges' threads at %d\n",
              xml.c_str(), domain, turns, seconds / turns, priority, g_thread_priority);

  crease::rt::HistogramSnapshot with, without, beside_perf;
  Collected got;
  // ddsperf on two domains of its own (one per sample size), beside the same loops.
  DdsPerf perf_hand(kHandStateBytes, 1000, 201 + (domain - 201 + 10) % 30, xml);
  DdsPerf perf_kp(kKeypointsBytes, 15, 201 + (domain - 201 + 20) % 30, xml);
  for (int t = 0; t < turns; ++t) {
    turn(false, seconds / turns, priority, cpu, domain, xml, creased, dir, without, got);
    turn(true, seconds / turns, priority, cpu, domain, xml, creased, dir, with, got);
    turn(false, seconds / turns, priority, cpu, domain, xml, creased, dir, beside_perf, got, {&perf_hand, &perf_kp});
  }
  fs::remove_all(dir);

  std::printf("\n  latency (us)                                       p50       p99       max   samples\n");
  std::vector<double> v;
  const char* names[2] = {"hand_state (144 B, 1 kHz)", "keypoints (16408 B, 15 Hz)"};
  Dist wire_sec[2];
  for (int k = 0; k < 2; ++k) {
    v.clear();
    for (const auto& [t, us] : got.wire[k]) v.push_back(us);
    print_row((std::string(names[k]) + ": port write -> bridge channel").c_str(), dist_of(v));
    wire_sec[k] = per_second(got.wire[k]);
    print_row("  same, median of per-second percentiles", wire_sec[k]);
    v.clear();
    for (const auto& [t, us] : got.port[k]) v.push_back(us);
    print_row("  to the reading plugin (next 1 kHz cycle)", dist_of(v));
  }
  const bool have_perf = perf_hand.ran() && perf_kp.ran();
  const Dist perf[2] = {perf_hand.one_way(), perf_kp.one_way()};
  if (have_perf) {
    print_row("ddsperf ping-pong 144 B, 1 kHz: round trip / 2", perf[0]);
    print_row("ddsperf ping-pong 16408 B, 15 Hz: round trip / 2", perf[1]);
  } else {
    std::printf("  ddsperf: printed no round trips (not installed, or its pong not discovered)\n");
  }
  const double w99 = double(with.percentile(99)) / 1e3, wo99 = double(without.percentile(99)) / 1e3;
  std::printf("\n  1 kHz loop wake-up (us)   p50 %7.1f  p99 %7.1f  max %8.1f  with the bridge (%llu cycles)\n",
              double(with.percentile(50)) / 1e3, w99, double(with.max_ns) / 1e3, (unsigned long long)with.count);
  std::printf("                            p50 %7.1f  p99 %7.1f  max %8.1f  without (%llu cycles)\n",
              double(without.percentile(50)) / 1e3, wo99, double(without.max_ns) / 1e3,
              (unsigned long long)without.count);
  const double ratio = have_perf ? crease::bench::ratio(wire_sec[0].p99, perf[0].p99) : std::nan("");
  const double kp_ratio = have_perf ? crease::bench::ratio(wire_sec[1].p99, perf[1].p99) : std::nan("");
  std::printf("  bridge / ddsperf one-way p99: hand_state %.2f, keypoints %.2f (target <= 1.5); loop p99 with / "
              "without %.2f (target <= 1.05)\n",
              ratio, kp_ratio, crease::bench::ratio(w99, wo99));
  std::printf("dds: p99_us=%.1f ddsperf_p99_us=%.1f ratio=%.2f loop_p99_ratio=%.2f\n", wire_sec[0].p99,
              have_perf ? perf[0].p99 * 2 : std::nan(""), ratio, crease::bench::ratio(w99, wo99));
  return have_perf && !got.wire[0].empty() ? 0 : 1;
}
}  // namespace

CREASE_BENCH(dds, "dds_bridge across two processes: port-to-port latency beside ddsperf, 1 kHz loop with and without",
             run);
