// The sheet_model plugin in a real loop of the plugin host: events in, sheet_state out, and
// its steady-state updates allocate nothing (the loop thread is RT-marked).
#include <doctest/doctest.h>

#include <chrono>
#include <memory>
#include <thread>

#include "core/plugin_host.h"
#include "core/port_types/sheet_state.h"
#include "rt/alloc_guard.h"

using namespace std::chrono_literals;

namespace {

struct Fixture {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  std::unique_ptr<crease::SheetState> state = std::make_unique<crease::SheetState>();
  Fixture() {
    host.add_loop({"model", 120.0, 0, -1});  // faster than the default 60 Hz: a shorter test
    crease::InstanceSpec s;
    s.name = "sheet";
    s.library = "sheet_model";
    s.loop = "model";
    s.params = crease::Params(YAML::Load("{substeps: 4}"), "test.yaml", "sheet.params");
    host.add_instance(s);
  }
  const crease::SheetState& read() {
    const auto* ch = host.ports().find_latest("sheet_state");
    REQUIRE(ch != nullptr);
    ch->read(state.get(), 0);
    return *state;
  }
  template <class P>
  bool wait_for(P pred) {
    for (int i = 0; i < 5000; ++i) {
      host.poll();
      if (pred()) return true;
      std::this_thread::sleep_for(1ms);
    }
    return false;
  }
};

}  // namespace

TEST_CASE_FIXTURE(Fixture, "the plugin publishes a finite sheet state and allocates nothing per update") {
  host.start();
  REQUIRE(wait_for([&] { return read().step > 20; }));
  const crease::SheetState& s = read();
  CHECK(s.all_finite());
  CHECK(s.nodes_u == 15);
  CHECK(s.nodes_v == 21);
  CHECK(s.link_count == 8722);
  CHECK(s.rollbacks == 0);
  // Resting on the table, the sheet stays flat at half a thickness.
  CHECK(s.position_mm[0][2] == doctest::Approx(0.5).epsilon(0.05));
  const auto before = crease::rt::rt_allocation_count();
  const auto at = read().step;
  CHECK(wait_for([&] { return read().step > at + 60; }));
  CHECK(crease::rt::rt_allocation_count() == before);
  host.stop();
}

TEST_CASE("self_collision_every is a validated parameter, named in the error") {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  host.add_loop({"model", 120.0, 0, -1});
  auto spec = [](const char* yaml) {
    crease::InstanceSpec s;
    s.name = "sheet";
    s.library = "sheet_model";
    s.loop = "model";
    s.params = crease::Params(YAML::Load(yaml), "test.yaml", "sheet.params");
    return s;
  };
  CHECK_THROWS_WITH_AS(host.add_instance(spec("{substeps: 4, self_collision_every: 0}")),
                       doctest::Contains("self_collision_every"), std::exception);
  CHECK_THROWS_WITH_AS(host.add_instance(spec("{substeps: 4, self_collision_every: 1000}")),
                       doctest::Contains("self_collision_every"), std::exception);
  CHECK_NOTHROW(host.add_instance(spec("{substeps: 4, self_collision_every: 1}")));
}
