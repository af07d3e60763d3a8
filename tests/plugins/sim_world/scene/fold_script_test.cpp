// The analytic fold scripts (the simulated world's sheet, plugins/sim_world/scene): flat before
// the fold, only the moving side turns and it turns rigidly about the crease, it ends over the
// fixed side, an unfold ends flat again, and a second fold carries the stack the first made.
#include "plugins/sim_world/scene/fold_script.h"

#include <doctest/doctest.h>

#include <cmath>
#include <initializer_list>

using crease::sheet::FoldScript;
using crease::sheet::GridParams;
using crease::sheet::Vec2;
using crease::sheet::Vec3;

namespace {
double dist(Vec3 a, Vec3 b) {
  const Vec3 d = a - b;
  return std::sqrt(dot(d, d));
}
Vec3 flat(const GridParams& g, Vec2 p) {  // flat sheet: u -> +x, v -> -y
  return {g.origin_mm.x + p.u, g.origin_mm.y - p.v, g.origin_mm.z};
}
}  // namespace

TEST_CASE("half fold: flat at the start, the top half turned rigidly over the bottom half") {
  const GridParams g;  // A4, 210 x 297 mm
  const FoldScript s = FoldScript::half_fold(g);
  CHECK(s.duration_s() == doctest::Approx(8.0));  // 5 s to 175 deg, 3 s held
  const double h2 = g.height_mm / 2;
  const Vec2 flap[] = {{20, 10}, {190, 60}, {105, h2 - 5}};  // v < h/2: the side that turns
  const Vec2 fixed[] = {{20, h2 + 5}, {190, 290}};
  for (const Vec2 p : flap) {
    const Vec3 x0 = s.position(p, 0.0);
    CHECK(dist(x0, flat(g, p)) < 1e-9);
  }
  for (const double t : {1.0, 2.5, 5.0, 8.0}) {
    CAPTURE(t);
    for (const Vec2 p : fixed) CHECK(dist(s.position(p, t), flat(g, p)) < 1e-9);
    // Rigid: distances between points of the flap are those of the flat sheet.
    for (const Vec2 a : flap)
      for (const Vec2 b : flap)
        CHECK(dist(s.position(a, t), s.position(b, t)) ==
              doctest::Approx(dist(flat(g, a), flat(g, b))).epsilon(1e-9));
  }
  // At the end the flap lies over the fixed half: above the sheet, beyond the crease line
  // (y below the crease's), each point at its own u. Mid-fold it stands up.
  const double y_crease = g.origin_mm.y - h2;
  for (const Vec2 p : flap) {
    const Vec3 x = s.position(p, 8.0);
    CAPTURE(p.v);
    CHECK(x.x == doctest::Approx(g.origin_mm.x + p.u));
    CHECK(x.y < y_crease);
    CHECK(x.z > g.origin_mm.z);
  }
  CHECK(s.position({105, 10}, 2.5).z > g.origin_mm.z + 0.5 * (h2 - 10));  // ~87 deg at 2.5 s
}

TEST_CASE("unfold ends flat; two folds: the second carries the stack the first made") {
  const GridParams g;
  const FoldScript u = FoldScript::unfold(g);
  for (const Vec2 p : {Vec2{20, 10}, Vec2{190, 60}}) {  // on the side that turns
    CHECK(dist(u.position(p, u.duration_s()), flat(g, p)) < 1e-6);
    CHECK(dist(u.position(p, 5.0), flat(g, p)) > 1.0);  // folded on the way
  }
  const FoldScript two = FoldScript::two_folds(g);
  REQUIRE(two.folds().size() == 2);
  // The top-right corner (on the first fold's flap and the second's moving side) ends on the
  // stack's top over the bottom-left quarter: x and y both on the other side of their creases.
  const Vec3 corner = two.position({200, 10}, two.duration_s());
  CHECK(corner.x < g.origin_mm.x + g.width_mm / 2);
  CHECK(corner.y < g.origin_mm.y - g.height_mm / 2);
  CHECK(corner.z > g.origin_mm.z + 0.5 * g.thickness_mm);
}
