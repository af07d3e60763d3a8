// Test support: a configuration's loops stepped on this thread in simulated time (each at its
// rate, interleaved by deadline), every cycle marked RT so the allocation guard counts it.
#pragma once

#include <cstdint>
#include <functional>
#include <map>

#include "core/plugin_host.h"
#include "rt/alloc_guard.h"

namespace crease::test {

// Runs `seconds` of simulated time from now_ns; after each cycle, on_cycle(loop) (not counted).
inline void run_cycles(PluginHost& host, double seconds, std::int64_t& now_ns, std::map<const Loop*, std::uint64_t>& cycle,
                       const std::function<void(const Loop&)>& on_cycle = {}) {
  const std::int64_t end = now_ns + static_cast<std::int64_t>(seconds * 1e9);
  std::map<const Loop*, std::int64_t> next;
  for (const Loop* l : host.loops()) next[l] = now_ns;
  while (true) {
    const Loop* due = nullptr;
    for (auto& [l, t] : next) {
      if (due == nullptr || t < next[due]) due = l;
    }
    if (next[due] >= end) break;
    now_ns = next[due];
    const rt::CycleClock clock{cycle[due]++, now_ns, now_ns, due->period_ns()};
    {
      rt::ScopedRtMark rt;  // only the cycle itself counts, not the test's bookkeeping
      const_cast<Loop*>(due)->run_cycle_rt(clock);
    }
    if (on_cycle) on_cycle(*due);
    next[due] += due->period_ns();
  }
}

}  // namespace crease::test
