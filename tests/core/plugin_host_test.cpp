#include "core/plugin_host.h"

#include <doctest/doctest.h>

#include <chrono>
#include <thread>

#include "core/errors.h"
#include "plugins/test_plugins/test_ports.h"
#include "rt/alloc_guard.h"
#include "support/host_poll.h"

using crease::test_plugins::TestValue;
using namespace std::chrono_literals;

namespace {
crease::InstanceSpec spec(const std::string& name, const std::string& lib, int order, const std::string& yaml = "{}",
                          std::map<std::string, std::string> ports = {}) {
  crease::InstanceSpec s;
  s.name = name;
  s.library = lib;
  s.loop = "control";
  s.order = order;
  s.params = crease::Params(YAML::Load(yaml), "test.yaml", name + ".params");
  s.ports = std::move(ports);
  return s;
}

struct Fixture {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  Fixture() { host.add_loop({"control", 1000.0, 0, -1}); }
  TestValue read(const std::string& port) {
    const auto* ch = host.ports().find_latest(port);
    REQUIRE(ch != nullptr);
    TestValue v{};
    ch->read(&v, 0);
    return v;
  }
  // Waits until `pred` holds (polling the host so events are processed), at most 3 s.
  template <class P>
  bool wait_for(P pred) {
    return crease::testing::poll_until(host, pred, std::chrono::seconds(3));
  }
  crease::RunState state(const std::string& name) {
    for (const auto& i : host.instances()) {
      if (i.name == name) return i.state;
    }
    return crease::RunState::inactive;
  }
};

std::string error_of(auto&& fn) {
  try {
    fn();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST_CASE_FIXTURE(Fixture, "instances run in their configured order and ports are remapped") {
  host.add_instance(spec("b", "crease_test_counter_v1", 20, "{}", {{"count", "b_count"}, {"counts", "b_counts"}}));
  host.add_instance(spec("a", "crease_test_counter_v2", 10, "{increment: 2}", {{"count", "a_count"}, {"counts", "a_counts"}}));
  const auto* sched = host.loops()[0]->schedule();
  REQUIRE(sched->entries.size() == 2);
  CHECK(sched->entries[0].instance->name() == "a");
  host.start();
  CHECK(wait_for([&] { return read("b_count").count > 50; }));
  const TestValue a = read("a_count");
  CHECK(a.version == 2);
  CHECK(a.value == doctest::Approx(2.0 * double(a.count)));
  host.stop();
  CHECK(read("a_count").version == 0);  // stopped: outputs at their safe values
}

TEST_CASE_FIXTURE(Fixture, "throw, NaN and fault each stop only that plugin, drive its outputs safe, and the loop goes on") {
  host.add_instance(spec("counter", "crease_test_counter_v1", 0));
  host.add_instance(spec("thrower", "crease_test_thrower", 1, "{after: 20}", {{"out", "thrower_out"}}));
  host.add_instance(spec("nan", "crease_test_nan", 2, "{after: 20}", {{"out", "nan_out"}}));
  host.add_instance(spec("faulty", "crease_test_faulty", 3, "{after: 20}", {{"out", "faulty_out"}}));
  std::vector<crease::HostEvent> seen;
  host.set_event_sink([&](const crease::HostEvent& e) { seen.push_back(e); });
  host.start();
  for (const char* name : {"thrower", "nan", "faulty"}) {
    CAPTURE(name);
    CHECK(wait_for([&] { return state(name) == crease::RunState::faulted; }));
  }
  const auto before = read("count").count;
  CHECK(wait_for([&] { return read("count").count > before + 100; }));  // the loop goes on
  for (const char* port : {"thrower_out", "nan_out", "faulty_out"}) {
    CAPTURE(port);
    CHECK(read(port).value == -1.0);  // the declared safe value
  }
  CHECK(host.fault_count() == 3);
  std::map<std::string, std::string> why;
  for (const auto& e : seen) {
    if (e.type == crease::HostEvent::Type::fault) why[e.instance] = e.detail;
  }
  CHECK(why["thrower"] == "threw an exception");
  CHECK(why["nan"] == "wrote a non-finite output");
  CHECK(why["faulty"] == "returned fault");
  CHECK(state("counter") == crease::RunState::active);

  // Activated again, a faulted plugin runs until it misbehaves again (its count carries on).
  // It faults again on its very next cycle, so its state right after activate() races the loop
  // thread: check what is certain, that it ran again and was stopped again.
  auto updates_of = [&](const std::string& name) {
    for (const auto& i : host.instances())
      if (i.name == name) return i.stats->updates.load();
    return std::uint64_t{0};
  };
  const auto updates_before = updates_of("faulty");
  host.activate("faulty");
  CHECK(wait_for([&] { return host.fault_count() == 4; }));
  CHECK(updates_of("faulty") > updates_before);
  CHECK(wait_for([&] { return state("faulty") == crease::RunState::faulted; }));
  host.stop();
}

TEST_CASE_FIXTURE(Fixture, "refusals name the reason and leave running instances intact") {
  host.add_instance(spec("counter", "crease_test_counter_v1", 0));
  host.start();
  CHECK(wait_for([&] { return read("count").count > 10; }));
  CHECK(error_of([&] { host.add_instance(spec("x", "crease_test_wrong_abi", 1)); }).find("ABI 99") != std::string::npos);
  CHECK(error_of([&] { host.add_instance(spec("x", "crease_test_no_entry", 1)); }).find("no entry point") != std::string::npos);
  CHECK(error_of([&] { host.add_instance(spec("x", "/usr/lib/x86_64-linux-gnu/libm.so.6", 1)); }).find("outside") !=
        std::string::npos);
  CHECK(error_of([&] { host.add_instance(spec("x", "crease_test_counter_v2", 1, "{increment: 500}")); })
            .find("test.yaml:1:13: x.params.increment: must be in [0, 100], got 500") != std::string::npos);
  CHECK(error_of([&] { host.add_instance(spec("x", "crease_test_counter_v2", 1, "{incremnt: 5}", {{"count", "c2"}, {"counts", "c2s"}})); })
            .find("x.params.incremnt: unknown parameter") != std::string::npos);
  CHECK(error_of([&] { host.add_instance(spec("x", "crease_test_counter_v2", 1)); })
            .find("port 'count': instance 'x' cannot write it: instance 'counter' already does") != std::string::npos);
  CHECK(error_of([&] { host.add_instance(spec("x", "crease_test_counter_v2", 1, "{}", {{"count", "c3"}, {"counts", "c3s"}, {"cuont", "zz"}})); })
            .find("ports.cuont: the plugin has no port 'cuont'") != std::string::npos);
  CHECK(error_of([&] { host.add_instance(spec("counter", "crease_test_counter_v2", 1)); }).find("defined twice") !=
        std::string::npos);
  CHECK(error_of([&] { host.swap("counter", "crease_test_wrong_abi"); }).find("ABI 99") != std::string::npos);
  CHECK(host.instances().size() == 1);
  CHECK(state("counter") == crease::RunState::active);
  const auto before = read("count").count;
  CHECK(wait_for([&] { return read("count").count > before + 10; }));
  CHECK(read("count").version == 1);
  host.stop();
}

TEST_CASE_FIXTURE(Fixture, "tunables change at a cycle boundary after validation; deactivate drives outputs safe") {
  host.add_instance(spec("counter", "crease_test_counter_v1", 0));
  host.add_instance(spec("noop", "crease_test_noop", 1));
  host.start();
  CHECK(host.set_param("counter", "increment", 5.0).empty());
  CHECK(host.get_param("counter", "increment") == 5.0);
  CHECK(host.set_param("counter", "increment", 13.0) == "refused: 13 is unlucky");
  CHECK(host.set_param("counter", "increment", 1000.0).find("outside [0, 100]") != std::string::npos);
  CHECK(host.set_param("counter", "nope", 1.0).find("no tunable parameter 'nope'") != std::string::npos);
  CHECK(host.get_param("counter", "increment") == 5.0);
  const auto a = read("count");
  CHECK(wait_for([&] { return read("count").count > a.count + 10; }));
  const auto b = read("count");
  CHECK(b.value - a.value == doctest::Approx(5.0 * double(b.count - a.count)));

  host.deactivate("counter");
  CHECK(state("counter") == crease::RunState::inactive);
  CHECK(read("count").value == 0.0);  // the safe value: TestValue{}
  host.activate("counter");
  CHECK(wait_for([&] { return read("count").count > b.count + 10; }));
  host.stop();
}

TEST_CASE_FIXTURE(Fixture, "steady-state cycles of the test plugins allocate nothing, and the guard sees one that does") {
  host.add_instance(spec("counter", "crease_test_counter_v1", 0));
  host.add_instance(spec("noop", "crease_test_noop", 1));
  host.add_instance(spec("slow", "crease_test_slow", 2, "{busy_us: 5}", {{"out", "slow_out"}}));
  host.start();
  CHECK(wait_for([&] { return read("count").count > 50; }));
  const auto before = crease::rt::rt_allocation_count();
  const auto at = read("count").count;
  CHECK(wait_for([&] { return read("count").count > at + 300; }));
  CHECK(crease::rt::rt_allocation_count() == before);

  host.add_instance(spec("alloc", "crease_test_allocating", 3, "{after: 5}", {{"out", "alloc_out"}}));
  CHECK(wait_for([&] { return crease::rt::rt_allocation_count() > before + 10; }));
  host.stop();
}

TEST_CASE_FIXTURE(Fixture, "unload drives outputs safe and releases the ports") {
  host.add_instance(spec("counter", "crease_test_counter_v1", 0));
  host.start();
  CHECK(wait_for([&] { return read("count").count > 10; }));
  host.unload("counter");
  CHECK(host.instances().empty());
  CHECK(read("count").value == 0.0);
  host.add_instance(spec("counter2", "crease_test_counter_v2", 0));  // may now write `count`
  CHECK(wait_for([&] { return read("count").version == 2; }));
  host.stop();
}

// Several libraries share one plugin name (the misbehaving family is all "test_misbehaving"):
// the swap event names the library swapped in, by file, and the one it replaced.
TEST_CASE_FIXTURE(Fixture, "the swap event names the library swapped in and the one it replaced") {
  host.add_instance(spec("n", "crease_test_noop", 0, "{}", {{"out", "n_out"}}));
  std::vector<crease::HostEvent> seen;
  host.set_event_sink([&](const crease::HostEvent& e) { seen.push_back(e); });
  host.start();
  host.swap("n", "crease_test_slow");
  host.swap("n", "crease_test_faulty", crease::Params(YAML::Load("{after: 1000000}"), "test.yaml", "n.params"));
  host.stop();
  std::vector<std::string> swaps;
  for (const auto& e : seen) {
    if (e.type == crease::HostEvent::Type::swapped) swaps.push_back(e.detail);
  }
  REQUIRE(swaps.size() == 2);
  CHECK(swaps[0].rfind("libcrease_test_slow.so (test_misbehaving 1.0.0) from /", 0) == 0);
  CHECK(swaps[0].find(", replacing libcrease_test_noop.so") != std::string::npos);
  CHECK(swaps[1].rfind("libcrease_test_faulty.so (test_misbehaving 1.0.0)", 0) == 0);
  CHECK(swaps[1].find(", replacing libcrease_test_slow.so") != std::string::npos);
}
