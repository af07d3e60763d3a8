// crease-bench overhead: what the framework costs per cycle of a loop running 10 no-op plugins
// (schedule walk, state checks, tunables, per-plugin timing, the C ABI call), beside the same
// 10 no-op calls made through plain virtual functions in the same run.
#include <chrono>
#include <cstdio>
#include <memory>
#include <vector>

#include "bench_registry.h"
#include "bench_util.h"
#include "core/plugin_host.h"
#include "rt/clock.h"

namespace {
struct Base {
  virtual ~Base() = default;
  virtual int update(const crease::rt::CycleClock& c) noexcept = 0;
};
struct Noop final : Base {
  int update(const crease::rt::CycleClock& c) noexcept override { return static_cast<int>(c.cycle & 0); }
};

int run(int argc, char** argv) {
  const auto cycles = static_cast<std::uint64_t>(crease::bench::arg_double(argc, argv, "--cycles", 2e6));
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  crease::Loop& loop = host.add_loop({"bench", 1000.0, 0, -1});
  for (int i = 0; i < 10; ++i) {
    host.add_instance(crease::bench::instance("noop" + std::to_string(i), "crease_test_noop", "bench", "{}", i));
  }
  // The loop thread is not started: cycles run here, back to back, so only CPU cost is measured.
  crease::rt::CycleClock clock{0, 0, 0, 1'000'000};
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t i = 0; i < cycles; ++i) {
    clock.cycle = i;
    loop.run_cycle_rt(clock);
  }
  const auto t1 = std::chrono::steady_clock::now();

  std::vector<std::unique_ptr<Base>> plain;
  for (int i = 0; i < 10; ++i) plain.push_back(std::make_unique<Noop>());
  volatile int sink = 0;
  const auto t2 = std::chrono::steady_clock::now();
  for (std::uint64_t i = 0; i < cycles; ++i) {
    clock.cycle = i;
    for (auto& p : plain) sink = sink + p->update(clock);
  }
  const auto t3 = std::chrono::steady_clock::now();

  const double ours_ns = std::chrono::duration<double, std::nano>(t1 - t0).count() / double(cycles);
  const double plain_ns = std::chrono::duration<double, std::nano>(t3 - t2).count() / double(cycles);
  std::printf("overhead: one cycle of 10 no-op plugins, %llu cycles\n", (unsigned long long)cycles);
  std::printf("  crease loop (C ABI, firewall, per-plugin timing): %8.1f ns per cycle\n", ours_ns);
  std::printf("  plain virtual calls, no timing, no firewall:      %8.1f ns per cycle\n", plain_ns);
  std::printf("  framework cost: %.1f ns per cycle (%.1f ns per plugin); target <= 2000 ns\n", ours_ns - plain_ns,
              (ours_ns - plain_ns) / 10.0);
  std::printf("overhead: ours_ns_per_cycle=%.1f plain_ns_per_cycle=%.1f framework_ns=%.1f plugins=10\n", ours_ns,
              plain_ns, ours_ns - plain_ns);
  return 0;
}
}  // namespace

CREASE_BENCH(overhead, "framework cost per cycle of a loop with 10 no-op plugins", run);
