// 1000 hot-swaps of a counter in a running 1 kHz loop: the count never skips or repeats, the
// replaced library is really unmapped, and the loop thread allocates nothing while swapping.
#include <doctest/doctest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/plugin_host.h"
#include "plugins/test_plugins/test_ports.h"
#include "rt/alloc_guard.h"

using crease::test_plugins::TestValue;
using namespace std::chrono_literals;

namespace {
std::string maps() {
  std::ifstream f("/proc/self/maps");
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

#if defined(CREASE_SANITIZER_THREAD) || defined(CREASE_SANITIZER_ADDRESS)
constexpr int kSwaps = 200;  // sanitizers make dlopen slow; the mechanism is the same
#else
constexpr int kSwaps = 1000;
#endif
}  // namespace

TEST_CASE("hot-swaps carry the count across versions without a skip or a repeat") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"control", 1000.0, 0, -1});
  crease::InstanceSpec s;
  s.name = "counter";
  s.library = "crease_test_counter_v1";
  s.loop = "control";
  host.add_instance(s);
  crease::rt::QueueChannel* counts = host.ports().find_queue("counts");
  REQUIRE(counts != nullptr);
  host.start();

  std::uint64_t expected = 1, skips = 0, repeats = 0, version_switches = 0;
  std::int32_t last_version = 1;
  auto drain = [&] {
    TestValue v;
    while (counts->try_pop(&v)) {
      if (v.count > expected) ++skips;
      if (v.count < expected) ++repeats;
      if (v.version != last_version) ++version_switches;
      last_version = v.version;
      expected = v.count + 1;
    }
  };

  std::this_thread::sleep_for(20ms);
  const auto allocs_before = crease::rt::rt_allocation_count();
  bool unmapped = true;
  for (int i = 0; i < kSwaps; ++i) {
    const bool to_v2 = i % 2 == 0;
    host.swap("counter", to_v2 ? "crease_test_counter_v2" : "crease_test_counter_v1");
    // The replaced library is gone from the address space once swap() returns.
    const std::string gone = to_v2 ? "libcrease_test_counter_v1.so" : "libcrease_test_counter_v2.so";
    if (i % 50 == 0 || i == kSwaps - 1) unmapped = unmapped && maps().find(gone) == std::string::npos;
    drain();
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  std::this_thread::sleep_for(20ms);
  host.stop();
  drain();

  CHECK(crease::rt::rt_allocation_count() == allocs_before);
  CHECK(unmapped);
  CHECK(skips == 0);
  CHECK(repeats == 0);
  CHECK(counts->dropped() == 0);
  CHECK(version_switches == kSwaps);
  CHECK(expected > static_cast<std::uint64_t>(kSwaps));  // it kept counting between swaps
  std::uint64_t swap_events = 0;
  for (const auto& e : host.events()) swap_events += e.type == crease::HostEvent::Type::swapped;
  CHECK(swap_events == kSwaps);
}
