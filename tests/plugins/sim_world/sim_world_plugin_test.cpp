// The sim_world plugin in a PluginHost loop whose cycles the test runs itself (no thread, no
// wall clock): configure errors name file, line and key; world_state, sheet_truth and
// world_shapes are published (the truth at the world's grid or every other node of it, the
// shapes at the truth's rate or their own); a cycle allocates nothing.
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "core/plugin_host.h"
#include "core/port_types/sheet_state.h"
#include "core/port_types/world_shapes.h"
#include "core/port_types/world_state.h"
#include "rt/alloc_guard.h"

using namespace crease;

namespace {

const std::string kRobot = CREASE_SOURCE_DIR "/config/robot/crease_robot.yaml";

std::string unique_prefix(const char* tag) { return std::string("crease-t-") + tag + "-" + std::to_string(::getpid()); }

struct WorldRig {
  explicit WorldRig(const std::string& params_yaml) : host({CREASE_PLUGIN_DIR}) {
    host.add_loop({"world", 1000.0, 0, -1});
    InstanceSpec s;
    s.name = "world";
    s.library = "sim_world";
    s.loop = "world";
    s.params = Params(YAML::Load(params_yaml), "test.yaml", "plugins[0].params");
    s.budget_ns = 0;  // as config/sim.yaml: the world's step may take longer than a period (sanitizers)
    host.add_instance(s);
    loop = host.loops().front();
  }
  void cycles(int n) {
    for (int i = 0; i < n; ++i, ++cycle) {
      const std::int64_t t = 1'000'000'000 + static_cast<std::int64_t>(cycle) * 1'000'000;
      const_cast<Loop*>(loop)->run_cycle_rt({cycle, t, t, 1'000'000});
    }
  }
  template <class T>
  std::unique_ptr<T> read(const std::string& port) {
    auto v = std::make_unique<T>();
    const auto* ch = host.ports().find_latest(port);
    REQUIRE_MESSAGE(ch != nullptr, port);
    ch->read(v.get(), 0);
    return v;
  }
  PluginHost host;
  const Loop* loop = nullptr;
  std::uint64_t cycle = 0;
};

std::string error_of(const std::string& yaml) {
  try {
    WorldRig rig(yaml);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("sim_world: bad parameters are configuration errors naming file, line and key") {
  const std::string base = "{robot: " + kRobot + ", bus_prefix: " + unique_prefix("cfg");
  const std::string stride = error_of(base + ", truth_stride: 3}");
  CHECK(stride.find("test.yaml") != std::string::npos);
  CHECK(stride.find("plugins[0].params.truth_stride") != std::string::npos);
  CHECK(stride.find("nodes_u - 1 = 28") != std::string::npos);
  const std::string arm = error_of(base + ", arm_r_deg: [1, 2, 3]}");
  CHECK(arm.find("plugins[0].params.arm_r_deg: expected a list of 7 angles") != std::string::npos);
  const std::string nan = error_of(base + ", hand_l_deg: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, .nan]}");
  CHECK(nan.find("plugins[0].params.hand_l_deg: element 19") != std::string::npos);
  const std::string robot = error_of("{robot: no/such/robot.yaml, bus_prefix: " + unique_prefix("cfg") + "}");
  CHECK(robot.find("plugins[0].params.robot") != std::string::npos);
  CHECK(robot.find("no/such/robot.yaml") != std::string::npos);
  CHECK(error_of("{bus_prefix: " + unique_prefix("cfg") + "}").find("plugins[0].params.robot") != std::string::npos);
  CHECK(error_of(base + ", seed: -1}").find("plugins[0].params.seed") != std::string::npos);
  CHECK(error_of(base + ", frobnicate: 1}").find("frobnicate") != std::string::npos);
  // A prefix another simulated robot holds.
  WorldRig first(base + "}");
  const std::string taken = error_of(base + "}");
  CHECK(taken.find("plugins[0].params.bus_prefix") != std::string::npos);
  CHECK(taken.find("another simulated robot") != std::string::npos);
}

TEST_CASE("sim_world: world_state every step, sheet_truth at its rate and grid; a cycle allocates nothing") {
  SUBCASE("the world's grid") {
    WorldRig rig("{robot: " + kRobot + ", bus_prefix: " + unique_prefix("full") + ", truth_every_steps: 4}");
    rig.cycles(1);
    auto w = rig.read<WorldState>("world_state");
    CHECK(w->step == 1);
    CHECK(w->timestamp_ns == 1'000'000'000);  // stamped with the loop's clock
    auto s = rig.read<SheetState>("sheet_truth");
    CHECK(s->nodes_u == 29);
    CHECK(s->nodes_v == 41);
    CHECK(s->step == 1);
    rig.cycles(4);  // steps 2..5: the truth of step 5 (every 4th, from the first)
    CHECK(rig.read<WorldState>("world_state")->step == 5);
    CHECK(rig.read<SheetState>("sheet_truth")->step == 5);
    rig.cycles(3);
    CHECK(rig.read<SheetState>("sheet_truth")->step == 5);
  }
  SUBCASE("every other node: the tracking model's 15 x 21 grid") {
    WorldRig rig("{robot: " + kRobot + ", bus_prefix: " + unique_prefix("half") + ", truth_stride: 2, randomise: false}");
    rig.cycles(20);
    auto s = rig.read<SheetState>("sheet_truth");
    REQUIRE(s->nodes_u == 15);
    REQUIRE(s->nodes_v == 21);
    CHECK(s->width_mm == doctest::Approx(210.0));
    CHECK(s->link_count == 0);
    // Flat on the table, centred on the origin (not randomised): neighbours 15 mm apart.
    CHECK(s->position_mm[0][0] == doctest::Approx(-105.0).epsilon(1e-3));
    CHECK(s->position_mm[0][1] == doctest::Approx(148.5).epsilon(1e-3));
    CHECK(s->position_mm[1][0] - s->position_mm[0][0] == doctest::Approx(15.0).epsilon(1e-3));
    CHECK(s->position_mm[15][1] - s->position_mm[0][1] == doctest::Approx(-14.85).epsilon(1e-3));
    CHECK(s->position_mm[314][0] == doctest::Approx(105.0).epsilon(1e-3));
    CHECK(s->position_mm[314][1] == doctest::Approx(-148.5).epsilon(1e-3));
    CHECK(std::fabs(s->position_mm[157][2]) < 1.0);
    CHECK(s->normal[157][2] == doctest::Approx(1.0).epsilon(1e-3));
    // The hands parked beside the sheet, above the table, touching nothing.
    auto w = rig.read<WorldState>("world_state");
    for (const WorldHand& h : w->hand) {
      for (const WorldFingertip& t : h.tip) {
        CHECK(t.position_mm[2] > 80.0);
        CHECK(t.contact == 0);
      }
    }
    CHECK(w->sheet_table_contact_area_mm2 > 0.9 * 210 * 297);
  }
  SUBCASE("no allocation in a cycle") {
    WorldRig rig("{robot: " + kRobot + ", bus_prefix: " + unique_prefix("alloc") + ", truth_stride: 2}");
    rig.cycles(5);
    const auto before = rt::rt_allocation_count();
    {
      rt::ScopedRtMark rt;
      rig.cycles(40);
    }
    CHECK(rt::rt_allocation_count() == before);
    CHECK(rig.read<WorldState>("world_state")->step == 45);
    CHECK(rig.read<WorldShapes>("world_shapes")->step == 33);  // every 16th step from the first
  }
}

TEST_CASE("sim_world: world_shapes, every shape of the robot at the truth's rate or its own") {
  SUBCASE("at the truth's rate, with the truth") {
    WorldRig rig("{robot: " + kRobot + ", bus_prefix: " + unique_prefix("shapes") +
                 ", truth_every_steps: 4}");
    rig.cycles(1);
    auto sh = rig.read<WorldShapes>("world_shapes");
    CHECK(sh->step == 1);
    CHECK(sh->timestamp_ns == 1'000'000'000);
    rig.cycles(6);  // steps 2..7: the shapes of step 5, as the truth
    sh = rig.read<WorldShapes>("world_shapes");
    CHECK(sh->step == 5);
    CHECK(rig.read<SheetState>("sheet_truth")->step == 5);
    // Both arms and hands: 88 shapes of the shipped robot, each finite, of its size.
    CHECK(sh->count == 88);
    CHECK(sh->all_finite());
    int pads[2] = {}, arms = 0;
    for (std::uint32_t i = 0; i < sh->count; ++i) {
      const WorldShapes::Shape& s = sh->shapes[i];
      if (s.role == WorldShapes::Role::pad) ++pads[s.side];
      if (s.role == WorldShapes::Role::arm) ++arms;
      const float size = s.kind == WorldShapes::Kind::box
                             ? s.half_mm[0] + s.half_mm[1] + s.half_mm[2]
                             : s.radius_mm;
      CHECK(size > 0.5f);
      CHECK(size < 300.0f);
    }
    CHECK(pads[0] == 5);
    CHECK(pads[1] == 5);
    CHECK(arms > 0);
    // Each hand's index pad shape within a few mm of the pad frame world_state reports.
    auto w = rig.read<WorldState>("world_state");
    for (int side = 0; side < 2; ++side) {
      double nearest = 1e9;
      for (std::uint32_t i = 0; i < sh->count; ++i) {
        const WorldShapes::Shape& s = sh->shapes[i];
        if (s.role != WorldShapes::Role::pad || s.side != side) continue;
        const float* t = w->hand[side].tip[0].position_mm;
        nearest = std::min<double>(
            nearest,
            std::hypot(s.position_mm[0] - t[0], s.position_mm[1] - t[1], s.position_mm[2] - t[2]));
      }
      CAPTURE(side);
      CHECK(nearest < 10.0);
    }
  }
  SUBCASE("at its own rate") {
    WorldRig rig("{robot: " + kRobot + ", bus_prefix: " + unique_prefix("shapes3") +
                 ", shapes_every_steps: 3}");
    rig.cycles(8);  // steps 1..8: shapes of steps 1, 4, 7
    CHECK(rig.read<WorldShapes>("world_shapes")->step == 7);
    CHECK(rig.read<SheetState>("sheet_truth")->step == 1);
  }
}
