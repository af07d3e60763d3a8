// The sheet_model plugin in a real loop of the plugin host: events in, sheet_state out, and
// its steady-state updates allocate nothing (the loop thread is RT-marked).
#include <doctest/doctest.h>

#include <array>
#include <chrono>
#include <memory>
#include <thread>

#include "core/plugin_host.h"
#include "core/port_types/keypoints.h"
#include "core/port_types/sheet_state.h"
#include "plugins/sheet_model/synthetic_markers.h"
#include "rt/alloc_guard.h"
#include "rt/clock.h"
#include "support/host_poll.h"
#include "support/instance_spec.h"

using namespace std::chrono_literals;

namespace {

// The sheet instance in the model loop. No time budget: the tests check what the model
// computes, and a sanitizer build on a slow machine takes longer than the 120 Hz period.
crease::InstanceSpec sheet_spec(const char* yaml) {
  crease::InstanceSpec s = crease::testing::instance_spec("sheet", "sheet_model", "model", 0, yaml);
  s.budget_ns = 0;
  return s;
}

struct Fixture {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  std::unique_ptr<crease::SheetState> state = std::make_unique<crease::SheetState>();
  Fixture() {
    host.add_loop({"model", 120.0, 0, -1});  // faster than the default 60 Hz: a shorter test
    host.add_instance(sheet_spec("{substeps: 4}"));
  }
  const crease::SheetState& read() {
    const auto* ch = host.ports().find_latest("sheet_state");
    REQUIRE(ch != nullptr);
    ch->read(state.get(), 0);
    return *state;
  }
  template <class P>
  bool wait_for(P pred) {
    return crease::testing::poll_until(host, pred, std::chrono::seconds(5));
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
  CHECK_THROWS_WITH_AS(host.add_instance(sheet_spec("{substeps: 4, self_collision_every: 0}")),
                       doctest::Contains("self_collision_every"), std::exception);
  CHECK_THROWS_WITH_AS(host.add_instance(sheet_spec("{substeps: 4, self_collision_every: 1000}")),
                       doctest::Contains("self_collision_every"), std::exception);
  CHECK_NOTHROW(host.add_instance(sheet_spec("{substeps: 4, self_collision_every: 1}")));
}

TEST_CASE("coupling is springs or keypoints, anything else an error naming the key") {
  auto configure = [](const char* yaml) {  // one host each: the ports have one writer, one reader
    crease::PluginHost host{{CREASE_PLUGIN_DIR}};
    host.add_loop({"model", 120.0, 0, -1});
    host.add_instance(sheet_spec(yaml));
  };
  CHECK_THROWS_WITH_AS(configure("{substeps: 4, coupling: velocities}"),
                       doctest::Contains("sheet.params.coupling: must be springs or keypoints, not 'velocities'"),
                       std::exception);
  CHECK_THROWS_WITH_AS(configure("{substeps: 4, coupling: [springs]}"), doctest::Contains("coupling"),
                       std::exception);
  CHECK_NOTHROW(configure("{substeps: 4, coupling: springs}"));
  CHECK_NOTHROW(configure("{substeps: 4, coupling: keypoints}"));
}

// The sheet's mean height after 60 model steps while a test writer keeps showing the
// plugin the marker layout's key-points 40 mm above the flat sheet on the table.
double mean_z_after_lift(const char* params) {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  host.add_loop({"model", 120.0, 0, -1});
  host.add_instance(sheet_spec(params));
  auto* kp_port = host.ports().bind_latest_writer("keypoints", crease::port_type_of<crease::Keypoints>(), "test");
  auto kp = std::make_unique<crease::Keypoints>();
  const auto layout = crease::sheet::marker_keypoints(crease::sheet::SyntheticMarkerGrid{});
  kp->count = static_cast<std::uint32_t>(layout.size());
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const auto& m = layout[i];  // flat sheet: (u, 297 - v, 0.5) in world mm
    kp->points[i] = {{float(m.u), float(297.0 - m.v), 40.5f}, {float(m.u), float(m.v)}, 0.1f,
                     static_cast<std::uint16_t>(i / 5), static_cast<std::uint8_t>(i % 5), 0, 3};
  }
  auto state = std::make_unique<crease::SheetState>();
  const auto* out = host.ports().find_latest("sheet_state");
  REQUIRE(out != nullptr);
  host.start();
  bool done = false;
  for (int i = 0; i < 5000 && !done; ++i) {  // a fresh observation every poll: never stale
    kp->timestamp_ns = crease::rt::now_ns();
    ++kp->frame;
    kp_port->write(kp.get(), kp->timestamp_ns);
    host.poll();
    done = out->read(state.get(), 0).has_data() && state->step > 60;
    std::this_thread::sleep_for(1ms);
  }
  host.stop();
  REQUIRE(done);
  CHECK(state->all_finite());
  CHECK(state->observations == layout.size());
  double z = 0;
  const int n = state->nodes_u * state->nodes_v;
  for (int k = 0; k < n; ++k) z += state->position_mm[k][2];
  return z / n;
}

TEST_CASE("the coupling parameter reaches the model: springs, or key-point velocities of gain keypoint_gain_per_s") {
  const double springs = mean_z_after_lift("{substeps: 4, coupling: springs, keypoint_gain_per_s: 0}");
  const double keypoints = mean_z_after_lift("{substeps: 4, coupling: keypoints, keypoint_gain_per_s: 10}");
  const double keypoints_no_gain = mean_z_after_lift("{substeps: 4, coupling: keypoints, keypoint_gain_per_s: 0}");
  MESSAGE("mean height: springs " << springs << " mm, keypoints " << keypoints << " mm, keypoints at gain 0 "
                                  << keypoints_no_gain << " mm");
  CHECK(springs > 30.0);                // the springs lift it whatever the gain
  CHECK(keypoints > 20.0);              // lambda = 10/s: a 0.1 s time constant, 0.5 s here
  CHECK(keypoints_no_gain < 1.0);       // no pull at all: it stays on the table (0.5 mm)
}

TEST_CASE("turn_deg lays the flat sheet turned about its corner (0, 0); out of range it is an error naming the key") {
  auto corners = [](const char* params) {
    crease::PluginHost host{{CREASE_PLUGIN_DIR}};
    host.add_loop({"model", 120.0, 0, -1});
    host.add_instance(sheet_spec(params));
    auto state = std::make_unique<crease::SheetState>();
    const auto* out = host.ports().find_latest("sheet_state");
    REQUIRE(out != nullptr);
    host.start();
    const bool seen = crease::testing::poll_until(
        host, [&] { return out->read(state.get(), 0).has_data() && state->step > 2; }, std::chrono::seconds(5));
    host.stop();
    REQUIRE(seen);
    const int w = state->nodes_u, h = state->nodes_v;
    std::array<std::array<float, 2>, 3> c{};  // nodes (0, 0), (W-1, 0), (0, H-1): x, y
    const int k[3] = {0, w - 1, (h - 1) * w};
    for (int i = 0; i < 3; ++i) c[static_cast<std::size_t>(i)] = {state->position_mm[k[i]][0], state->position_mm[k[i]][1]};
    return c;
  };
  const auto turned = corners("{substeps: 4, origin_x_mm: 105, origin_y_mm: -148.5, turn_deg: 180}");
  CHECK(turned[0][0] == doctest::Approx(105.0).epsilon(0.01));
  CHECK(turned[0][1] == doctest::Approx(-148.5).epsilon(0.01));
  CHECK(turned[1][0] == doctest::Approx(-105.0).epsilon(0.01));  // u along -x
  CHECK(turned[2][1] == doctest::Approx(148.5).epsilon(0.01));   // v along +y
  // Failing variant: unturned, the same origin lays u along +x and v along -y.
  const auto plain = corners("{substeps: 4, origin_x_mm: 105, origin_y_mm: -148.5}");
  CHECK(plain[1][0] == doctest::Approx(315.0).epsilon(0.01));
  CHECK(plain[2][1] == doctest::Approx(-445.5).epsilon(0.01));
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  host.add_loop({"model", 120.0, 0, -1});
  CHECK_THROWS_WITH_AS(host.add_instance(sheet_spec("{substeps: 4, turn_deg: 200}")), doctest::Contains("sheet.params.turn_deg"),
                       std::exception);
}
