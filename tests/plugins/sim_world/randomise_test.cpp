// One seed, one world: the same draws every time, each within its range, another seed others,
// and the nominal values with randomisation off.
#include "plugins/sim_world/randomise.h"

#include <doctest/doctest.h>

#include <cmath>

#include "scene.h"

using namespace scene;

TEST_CASE("the draws of a seed: repeatable, within their ranges, different for another seed") {
  const robot::RobotParams& rp = robot_model().params();
  WorldParams p;
  p.seed = 42;
  const WorldDraws a = draw_world(p, rp), b = draw_world(p, rp);
  CHECK(describe(p.seed, a) == describe(p.seed, b));
  CHECK(std::fabs(a.sheet_dx_mm) <= p.sheet_offset_mm);
  CHECK(std::fabs(a.sheet_dy_mm) <= p.sheet_offset_mm);
  CHECK(std::fabs(a.sheet_yaw_deg) <= p.sheet_yaw_deg);
  CHECK(std::fabs(a.stiffness_scale - 1) <= p.stiffness_fraction);
  CHECK(std::fabs(a.yield_scale - 1) <= p.yield_fraction);
  CHECK(std::fabs(a.paper_table / rp.paper_table_friction - 1) <= p.friction_fraction);
  CHECK(std::fabs(a.paper_paper / rp.paper_paper_friction - 1) <= p.friction_fraction);
  for (const auto& [name, mu] : a.material_friction) CHECK(std::fabs(mu / rp.materials.at(name) - 1) <= p.friction_fraction);
  p.seed = 43;
  const WorldDraws c = draw_world(p, rp);
  CHECK(c.sheet_dx_mm != a.sheet_dx_mm);
  CHECK(describe(p.seed, c).find("seed 43") == 0);
  p.randomise = false;
  const WorldDraws n = draw_world(p, rp);
  CHECK(n.sheet_dx_mm == 0.0);
  CHECK(n.stiffness_scale == 1.0);
  CHECK(n.paper_table == rp.paper_table_friction);
  CHECK(n.material_friction.at("rubber") == rp.materials.at("rubber"));
}

TEST_CASE("splitmix64: the reference sequence, and symmetric() in [-1, 1)") {
  SplitMix64 r(1234567);
  // The first outputs of Vigna's reference implementation for seed 1234567.
  CHECK(r.next() == 6457827717110365317ull);
  CHECK(r.next() == 3203168211198807973ull);
  SplitMix64 s(7);
  for (int i = 0; i < 10000; ++i) {
    const double v = s.symmetric();
    CHECK(v >= -1.0);
    CHECK(v < 1.0);
  }
}
