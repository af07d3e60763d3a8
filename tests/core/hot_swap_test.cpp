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

// Two loops whose changes are always adopted late (a timeout of 0 against 10 ms and 7.7 ms
// periods), hot-swapped from two threads at once: each replaced instance must live until its
// own loop has moved past it (freeing it when the other loop acknowledges is a use after free
// that ASan and TSan see), a loop with a change pending refuses the next one ("retry"), and
// the counts carry over with no skip or repeat.
TEST_CASE("hot-swaps in two loops at once, adopted late: each instance freed after its own loop let go") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"a", 100.0, 0, -1});
  host.add_loop({"b", 130.0, 0, -1});
  for (const std::string loop : {"a", "b"}) {
    crease::InstanceSpec s;
    s.name = loop + "_counter";
    s.library = "crease_test_counter_v1";
    s.loop = loop;
    s.ports = {{"count", loop + "_count"}, {"counts", loop + "_counts"}};
    host.add_instance(s);
  }
  host.set_adopt_timeout(0ms);
  host.start();
#if defined(CREASE_SANITIZER_THREAD) || defined(CREASE_SANITIZER_ADDRESS)
  constexpr int kPerLoop = 40;
#else
  constexpr int kPerLoop = 100;
#endif
  struct Result {
    std::uint64_t skips = 0, repeats = 0, counted = 0, refused = 0;
  };
  auto swapper = [&](const std::string& loop, Result& r) {
    crease::rt::QueueChannel* counts = host.ports().find_queue(loop + "_counts");
    std::uint64_t expected = 1;
    auto drain = [&] {
      TestValue v;
      while (counts->try_pop(&v)) {
        r.skips += v.count > expected;
        r.repeats += v.count < expected;
        expected = v.count + 1;
        ++r.counted;
      }
    };
    for (int i = 0; i < kPerLoop; ++i) {
      const char* lib = i % 2 == 0 ? "crease_test_counter_v2" : "crease_test_counter_v1";
      for (;;) {
        try {
          host.swap(loop + "_counter", lib);
          break;
        } catch (const crease::Error& e) {
          REQUIRE(std::string(e.what()).find("retry") != std::string::npos);
          ++r.refused;
          host.poll();
          drain();
          std::this_thread::sleep_for(200us);
        }
      }
      drain();
    }
    for (int i = 0; i < 2000 && host.retired_count() != 0; ++i) {
      host.poll();
      drain();
      std::this_thread::sleep_for(1ms);
    }
    drain();
  };
  Result ra, rb;
  std::thread ta([&] { swapper("a", ra); });
  std::thread tb([&] { swapper("b", rb); });
  ta.join();
  tb.join();
  host.stop();
  CHECK(host.retired_count() == 0);
  for (const Result* r : {&ra, &rb}) {
    CHECK(r->skips == 0);
    CHECK(r->repeats == 0);
    CHECK(r->counted > 0);
    CHECK(r->refused > 0);  // late adoptions really happened
  }
  std::uint64_t swap_events = 0;
  for (const auto& e : host.events()) swap_events += e.type == crease::HostEvent::Type::swapped;
  CHECK(swap_events == 2 * kPerLoop);
}
