// For tests that run a PluginHost's real loops: wait for a condition while polling the host, so
// the loops' events (faults, swaps, deactivations) are taken as the daemon takes them.
#pragma once

#include <chrono>
#include <thread>

#include "core/plugin_host.h"

namespace crease::testing {

// Polls `host` and checks `pred` every `step` until it holds (true) or `limit` has passed (false).
template <class Pred>
bool poll_until(PluginHost& host, Pred&& pred, std::chrono::milliseconds limit = std::chrono::seconds(10),
                std::chrono::milliseconds step = std::chrono::milliseconds(1)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < until) {
    host.poll();
    if (pred()) return true;
    std::this_thread::sleep_for(step);
  }
  host.poll();
  return pred();
}

}  // namespace crease::testing
