// crease-bench overhead: what the framework costs per cycle of a loop running 10 no-op plugins
// (schedule walk, state checks, tunables, per-plugin timing, the C ABI call), beside the same
// 10 no-op calls made through plain virtual functions in the same run; then what counting the
// plugins' heap allocations adds (the loop reads its thread's allocation counter before and
// after each hook), with and without it in interleaved turns so a neighbour's load falls on
// both alike, the same for the time budget's per-cycle sample of the thread's CPU clock (which
// keeps preemption out of a plugin's charge), and what the counting operator new adds to one
// allocation off the RT threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "bench_registry.h"
#include "bench_util.h"
#include "core/plugin_host.h"
#include "rt/alloc_guard.h"
#include "rt/clock.h"
#include "rt/thread_cpu.h"

namespace {
struct Base {
  virtual ~Base() = default;
  virtual int update(const crease::rt::CycleClock& c) noexcept = 0;
};
struct Noop final : Base {
  int update(const crease::rt::CycleClock& c) noexcept override { return static_cast<int>(c.cycle & 0); }
};

double ns_per(std::chrono::steady_clock::duration d, std::uint64_t n) {
  return std::chrono::duration<double, std::nano>(d).count() / double(n);
}

// new/delete (the counting hooks: crease-bench links them, as creased does) against
// malloc/free, on a thread that is not RT-marked; interleaved turns.
void allocation_hook_cost(std::uint64_t n) {
  constexpr int kTurns = 10;
  std::chrono::steady_clock::duration hooked{}, plain{};
  void* volatile keep = nullptr;
  for (int turn = 0; turn < kTurns; ++turn) {
    auto t0 = std::chrono::steady_clock::now();
    for (std::uint64_t i = 0; i < n / kTurns; ++i) {
      int* p = new int(static_cast<int>(i));
      keep = p;
      delete p;
    }
    auto t1 = std::chrono::steady_clock::now();
    for (std::uint64_t i = 0; i < n / kTurns; ++i) {
      void* p = std::malloc(sizeof(int));
      keep = p;
      std::free(p);
    }
    auto t2 = std::chrono::steady_clock::now();
    hooked += t1 - t0;
    plain += t2 - t1;
  }
  (void)keep;
  const double h = ns_per(hooked, n), m = ns_per(plain, n);
  std::printf("  new + delete through the counting hooks (non-RT thread): %6.1f ns; malloc + free: %6.1f ns; hook: %+.1f ns\n",
              h, m, h - m);
  std::printf("overhead_alloc_hook: hooked_ns=%.1f malloc_ns=%.1f hook_ns=%.1f\n", h, m, h - m);
}

constexpr int kTurns = 40;

struct Paired {
  double on = 0, off = 0, diff = 0;  // medians: ns per cycle with the setting on, off, and of the pairs' differences
};

// Runs the loop's cycles in kTurns pairs, one half of each pair with `set(true)` and one with
// `set(false)`, alternating which goes first.
template <class Set>
Paired paired_turns(crease::Loop& loop, crease::rt::CycleClock& clock, std::uint64_t cycles, Set set) {
  std::vector<double> on_ns, off_ns, diff_ns;
  for (int turn = 0; turn < kTurns; ++turn) {
    double pair[2] = {0, 0};
    for (const bool on : {turn % 2 == 0, turn % 2 != 0}) {
      set(on);
      const auto a = std::chrono::steady_clock::now();
      for (std::uint64_t i = 0; i < cycles / kTurns; ++i) {
        ++clock.cycle;
        loop.run_cycle_rt(clock);
      }
      pair[on ? 0 : 1] = ns_per(std::chrono::steady_clock::now() - a, cycles / kTurns);
    }
    on_ns.push_back(pair[0]);
    off_ns.push_back(pair[1]);
    diff_ns.push_back(pair[0] - pair[1]);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  return {median(on_ns), median(off_ns), median(diff_ns)};
}

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

  // Allocation counting, and the time budget's CPU-clock sample, each on and off in 40 paired
  // turns on an RT-marked thread (as a loop's): the median of the pairs' differences, so a
  // neighbour's burst spoils a few pairs, not the figure.
  {
    const crease::rt::ScopedRtMark rt_mark;
    const Paired counting = paired_turns(loop, clock, cycles, [&](bool on) { loop.set_count_allocations(on); });
    loop.set_count_allocations(true);
    std::printf("  allocation counting on: %8.1f ns per cycle; off: %8.1f ns per cycle (medians of %d turns); "
                "counting: %+.1f ns per cycle (median of the pairs' differences, %+.2f ns per plugin)\n",
                counting.on, counting.off, kTurns, counting.diff, counting.diff / 10.0);
    std::printf("overhead_alloc_count: on_ns_per_cycle=%.1f off_ns_per_cycle=%.1f counting_ns=%.1f plugins=10\n",
                counting.on, counting.off, counting.diff);
    const Paired sampling = paired_turns(loop, clock, cycles, [&](bool on) { loop.set_discount_preemption(on); });
    loop.set_discount_preemption(true);
    // What one sample costs: the loop takes two per cycle only after a cycle over budget.
    constexpr int kSamples = 100'000;
    std::int64_t sink_ns = 0;
    const auto s0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kSamples; ++i) sink_ns += crease::rt::sample_thread_cpu().cpu_ns & 1;
    const double sample_ns = ns_per(std::chrono::steady_clock::now() - s0, kSamples);
    std::printf("  time budget's preemption discount on: %8.1f ns per cycle; off: %8.1f ns per cycle; difference: "
                "%+.1f ns per cycle with no plugin over budget; one CPU-clock sample (taken only after a cycle over "
                "budget): %.1f ns%s\n",
                sampling.on, sampling.off, sampling.diff, sample_ns, sink_ns < 0 ? "" : "");
    std::printf("overhead_budget_clock: on_ns_per_cycle=%.1f off_ns_per_cycle=%.1f discount_ns=%.1f sample_ns=%.1f "
                "plugins=10\n",
                sampling.on, sampling.off, sampling.diff, sample_ns);
  }
  allocation_hook_cost(cycles * 5);
  return 0;
}
}  // namespace

CREASE_BENCH(overhead, "framework cost per cycle of a loop with 10 no-op plugins", run);
