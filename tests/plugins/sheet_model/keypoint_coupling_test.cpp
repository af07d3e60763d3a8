// Seed 000's key-point coupling (Eqs. 1-4) on small hand-made cases: which nodes it moves, by
// how much, and what it leaves alone.
#include "plugins/sheet_model/keypoint_coupling.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "plugins/sheet_model/xpbd_sheet.h"
#include "rt/alloc_guard.h"

using namespace crease::sheet;

namespace {

// A 15 x 21 sheet (du = 15 mm, dv = 14.85 mm) for its grid and stencils; nodes at their flat
// positions, all at rest unless a case says otherwise.
struct Scene {
  XpbdSheet sheet{SheetParams{}};
  std::vector<Vec3> x{sheet.positions().begin(), sheet.positions().end()};
  std::vector<Vec3> v = std::vector<Vec3>(x.size());
  std::vector<std::uint8_t> pinned = std::vector<std::uint8_t>(x.size(), 0);
  std::vector<KeypointObs> kps;
  std::vector<SheetPointStencil> stencils;
  KeypointCoupling coupling;
  Scene() { coupling.configure(sheet.node_count()); }
  void observe(Vec2 sheet_mm, Vec3 world_mm) {
    kps.push_back({world_mm, sheet_mm});
    stencils.push_back(sheet.stencil(sheet_mm));
  }
  std::vector<std::int32_t> apply(double gain, double dt) {
    const auto t = coupling.apply_rt(kps, stencils, gain, dt, x, v, pinned);
    return {t.begin(), t.end()};
  }
  [[nodiscard]] int node(int i, int j) const { return sheet.grid().index(i, j); }
  [[nodiscard]] Vec2 at(int node) const { return sheet.grid().sheet_of(node); }
};

constexpr double kDt = 1.0 / 600;  // one substep of the default 10 per 1/60 s frame

}  // namespace

TEST_CASE("Eq. 4: a key-point on a node moves that node alone at lambda (k - n)") {
  Scene s;
  const int q = s.node(4, 6);
  s.observe(s.at(q), s.x[q] + Vec3{3, -2, 10});
  const auto touched = s.apply(10.0, kDt);
  REQUIRE(touched.size() == 1);
  CHECK(touched[0] == q);
  CHECK(s.v[q].x == doctest::Approx(30.0));
  CHECK(s.v[q].y == doctest::Approx(-20.0));
  CHECK(s.v[q].z == doctest::Approx(100.0));
  for (int i = 0; i < s.sheet.node_count(); ++i)
    if (i != q) CHECK(norm(s.v[i]) == 0.0);
}

TEST_CASE("Eqs. 1-3: between nodes each gets alpha v_l, blended with its own velocity below W = 1") {
  Scene s;
  // The centre of cell (2, 3): 4 nodes at 1/sqrt(2) grid units, alpha = 1 - 1/sqrt(2).
  const Vec2 m{2.5 * 15.0, 3.5 * 14.85};
  const Vec3 c = s.sheet.interpolate(m);
  const Vec3 own{5, 0, 0};
  for (Vec3& v : s.v) v = own;
  s.observe(m, c + Vec3{0, 0, 4});
  const auto touched = s.apply(10.0, kDt);
  CHECK(touched.size() == 4);
  const double alpha = 1.0 - std::sqrt(0.5);
  for (const int q : {s.node(2, 3), s.node(3, 3), s.node(2, 4), s.node(3, 4)}) {
    CAPTURE(q);
    CHECK(std::find(touched.begin(), touched.end(), q) != touched.end());
    CHECK(s.v[q].x == doctest::Approx((1 - alpha) * 5.0));
    CHECK(s.v[q].z == doctest::Approx(alpha * 10.0 * 4.0));
  }
  CHECK(s.v[s.node(4, 3)].x == 5.0);  // outside the stencil: untouched
}

TEST_CASE("contributions accumulate: with W >= 1 a node takes their sum") {
  Scene s;
  const int q = s.node(5, 5);
  // Two key-points on the node (alpha 1 each, W = 2) asking for +z and +x.
  s.observe(s.at(q), s.x[q] + Vec3{0, 0, 2});
  s.observe(s.at(q), s.x[q] + Vec3{1, 0, 0});
  s.v[q] = {100, 100, 100};
  REQUIRE(s.apply(10.0, kDt).size() == 1);
  CHECK(s.v[q].x == doctest::Approx(10.0));
  CHECK(s.v[q].y == doctest::Approx(0.0));
  CHECK(s.v[q].z == doctest::Approx(20.0));
  // The accumulators start from zero again: the same call gives the same velocities.
  REQUIRE(s.apply(10.0, kDt).size() == 1);
  CHECK(s.v[q].x == doctest::Approx(10.0));
}

TEST_CASE("a gain of 0 changes nothing; a gain above 1/dt is clamped to 1/dt") {
  Scene s;
  const int q = s.node(7, 10);
  s.observe(s.at(q), s.x[q] + Vec3{0, 0, 6});
  s.v[q] = {1, 2, 3};
  CHECK(s.apply(0.0, kDt).empty());
  CHECK(s.v[q].x == 1.0);
  CHECK(s.v[q].z == 3.0);
  CHECK(s.apply(1e9, 0.01).size() == 1);
  CHECK(s.v[q].z == doctest::Approx(600.0));  // 6 mm in one step of 0.01 s
}

TEST_CASE("pinned nodes and empty inputs are left alone") {
  Scene s;
  const int q = s.node(1, 1);
  s.pinned[q] = 1;
  s.observe(s.at(q), s.x[q] + Vec3{0, 0, 6});
  CHECK(s.apply(10.0, kDt).empty());
  CHECK(norm(s.v[q]) == 0.0);
  s.kps.clear();
  s.stencils.clear();
  CHECK(s.apply(10.0, kDt).empty());
}

TEST_CASE("apply_rt allocates nothing") {
  Scene s;
  for (int k = 0; k < 200; ++k) s.observe({1.0 * k, 1.4 * k}, {1.0 * k, 0, 5});
  (void)s.apply(10.0, kDt);
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark mark;
    for (int i = 0; i < 10; ++i) (void)s.coupling.apply_rt(s.kps, s.stencils, 10.0, kDt, s.x, s.v, s.pinned);
  }
  CHECK(crease::rt::rt_allocation_count() == before);
}
