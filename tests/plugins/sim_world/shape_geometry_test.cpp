// The shapes' queries by hand: signed distance, closest point and normal of each kind (boxes
// rounded by their smallest half extent), the core, the lowest point, the bounding box.
#include "plugins/sim_world/shape_geometry.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

using namespace crease::world;

namespace {

// Turned by A about x, at T.
Pose turned_x(double a, Vec3 t) {
  Pose p;
  const double c = std::cos(a), s = std::sin(a);
  const double r[9] = {1, 0, 0, 0, c, -s, 0, s, c};
  for (int k = 0; k < 9; ++k) p.r[k] = r[k];
  p.t = t;
  return p;
}

void check_vec(Vec3 a, Vec3 b, double eps = 1e-9) {
  CHECK(a.x == doctest::Approx(b.x).epsilon(eps).scale(1.0));
  CHECK(a.y == doctest::Approx(b.y).epsilon(eps).scale(1.0));
  CHECK(a.z == doctest::Approx(b.z).epsilon(eps).scale(1.0));
}

}  // namespace

TEST_CASE("sphere and capsule: distance to the core minus the radius, normal out of the core") {
  const Geom sphere{GeomKind::sphere, 5.0, 0.0, {}};
  const Pose at{{1, 0, 0, 0, 1, 0, 0, 0, 1}, {10, 0, 0}};
  SurfacePoint s = closest_surface(sphere, at, {10, 0, 12});
  CHECK(s.distance_mm == doctest::Approx(7.0));
  check_vec(s.normal, {0, 0, 1});
  check_vec(s.point, {10, 0, 5});
  s = closest_surface(sphere, at, {10, 3, 0});  // inside
  CHECK(s.distance_mm == doctest::Approx(-2.0));
  check_vec(s.normal, {0, 1, 0});
  // A capsule along the world y (its z turned by -90 deg about x), half length 10.
  const Geom capsule{GeomKind::capsule, 2.0, 10.0, {}};
  const Pose cp = turned_x(-std::numbers::pi / 2, {0, 0, 0});
  s = closest_surface(capsule, cp, {0, 4, 5});  // beside the segment
  CHECK(s.distance_mm == doctest::Approx(3.0));
  check_vec(s.normal, {0, 0, 1});
  s = closest_surface(capsule, cp, {0, 15, 0});  // beyond its end: the cap
  CHECK(s.distance_mm == doctest::Approx(3.0));
  check_vec(s.normal, {0, 1, 0});
  check_vec(closest_core(capsule, cp, {3, 4, 5}), {0, 4, 0});
  check_vec(closest_core(capsule, cp, {3, -40, 5}), {0, -10, 0});
}

TEST_CASE("box: rounded by its smallest half extent, so the normal turns smoothly round an edge") {
  const Geom box{GeomKind::box, 0, 0, {9, 7, 1}};
  const Pose id;
  SurfacePoint s = closest_surface(box, id, {0, 0, 3});  // over the face
  CHECK(s.distance_mm == doctest::Approx(2.0));
  check_vec(s.normal, {0, 0, 1});
  s = closest_surface(box, id, {0, 0, 0.5});  // inside, under the face
  CHECK(s.distance_mm == doctest::Approx(-0.5));
  check_vec(s.normal, {0, 0, 1});
  // Beyond the edge at x = 9, 45 degrees out: the edge's rounding (radius 1 round x = 8).
  s = closest_surface(box, id, {8 + 2 / std::sqrt(2.0), 0, 2 / std::sqrt(2.0)});
  CHECK(s.distance_mm == doctest::Approx(1.0));
  check_vec(s.normal, {1 / std::sqrt(2.0), 0, 1 / std::sqrt(2.0)});
  check_vec(closest_core(box, id, {20, 20, 20}), {8, 6, 0});
}

TEST_CASE("cylinder: side, cap and rim") {
  const Geom cyl{GeomKind::cylinder, 3.0, 5.0, {}};
  const Pose id;
  SurfacePoint s = closest_surface(cyl, id, {6, 0, 0});
  CHECK(s.distance_mm == doctest::Approx(3.0));
  check_vec(s.normal, {1, 0, 0});
  s = closest_surface(cyl, id, {1, 0, 8});
  CHECK(s.distance_mm == doctest::Approx(3.0));
  check_vec(s.normal, {0, 0, 1});
  s = closest_surface(cyl, id, {6, 0, 9});  // beyond the rim
  CHECK(s.distance_mm == doctest::Approx(5.0));
  check_vec(s.normal, {0.6, 0, 0.8});
  s = closest_surface(cyl, id, {0, 0, 4.5});  // inside near the cap
  CHECK(s.distance_mm == doctest::Approx(-0.5));
  check_vec(s.normal, {0, 0, 1});
}

TEST_CASE("the lowest point and the bounding box hold every kind, turned") {
  const Geom geoms[] = {{GeomKind::sphere, 4, 0, {}}, {GeomKind::capsule, 2, 6, {}}, {GeomKind::cylinder, 3, 5, {}},
                        {GeomKind::box, 0, 0, {9, 7, 1}}};
  const Pose pose = turned_x(0.7, {1, 2, 30});
  for (const Geom& g : geoms) {
    const Vec3 low = lowest_point(g, pose);
    // On the surface, and no surface point found below it along a sweep of directions.
    CHECK(std::fabs(closest_surface(g, pose, low).distance_mm) < 1e-9);
    for (int i = 0; i < 400; ++i) {
      const double th = std::numbers::pi * (i % 20) / 19.0, ph = 2 * std::numbers::pi * (i / 20) / 20.0;
      const Vec3 dir{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
      const Vec3 far = pose.t + 50.0 * dir;
      const SurfacePoint s = closest_surface(g, pose, far);
      CHECK(s.point.z >= low.z - 1e-9);
      for (int a = 0; a < 3; ++a) {
        const double c = a == 0 ? s.point.x - pose.t.x : a == 1 ? s.point.y - pose.t.y : s.point.z - pose.t.z;
        CHECK(std::fabs(c) <= half_extent(g, pose, a) + 1e-9);
      }
    }
  }
}

TEST_CASE("the core's distance less core_grow bounds the distance to every kind from below, exactly but for a cylinder") {
  const Geom geoms[] = {{GeomKind::sphere, 4, 0, {}}, {GeomKind::capsule, 2, 6, {}}, {GeomKind::cylinder, 3, 5, {}},
                        {GeomKind::box, 0, 0, {9, 7, 1}}};
  const Pose pose = turned_x(0.7, {1, 2, 30});
  for (const Geom& g : geoms) {
    CAPTURE(static_cast<int>(g.kind));
    double loosest = 0;
    for (int i = 0; i < 400; ++i) {
      const double th = std::numbers::pi * (i % 20) / 19.0, ph = 2 * std::numbers::pi * (i / 20) / 20.0;
      const Vec3 dir{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
      for (double r : {0.5, 3.0, 8.0, 20.0}) {  // inside some kinds, on their surface, outside
        const Vec3 p = pose.t + r * dir;
        const double bound = norm(closest_core(g, pose, p) - p) - core_grow(g);
        const double d = closest_surface(g, pose, p).distance_mm;
        if (d < 0) continue;  // inside: the bound is for points outside (the contacts' skip)
        CHECK(bound <= d + 1e-9);
        loosest = std::max(loosest, d - bound);
      }
    }
    if (g.kind == GeomKind::cylinder) CHECK(loosest > 0.1);  // its rim is inside the capsule
    else CHECK(loosest < 1e-9);
  }
}

TEST_CASE("the bounding radius holds every kind's surface, turned") {
  const Geom geoms[] = {{GeomKind::sphere, 4, 0, {}},
                        {GeomKind::capsule, 2, 6, {}},
                        {GeomKind::cylinder, 3, 5, {}},
                        {GeomKind::box, 0, 0, {9, 7, 1}}};
  const Pose pose = turned_x(0.7, {1, 2, 30});
  for (const Geom& g : geoms) {
    double farthest = 0;
    for (int i = 0; i < 400; ++i) {
      const double th = std::numbers::pi * (i % 20) / 19.0,
                   ph = 2 * std::numbers::pi * (i / 20) / 20.0;
      const Vec3 dir{std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
      const SurfacePoint s = closest_surface(g, pose, pose.t + 50.0 * dir);
      farthest = std::max(farthest, norm(s.point - pose.t));
    }
    CHECK(farthest <= bounding_radius(g) + 1e-9);
    CHECK(farthest >= 0.9 * bounding_radius(g));  // not a loose bound
  }
}

TEST_CASE("closest_cores: two crossed capsules' axes meet at their common perpendicular") {
  // A capsule along z at the origin, one along x (turned about y) through (3, 10, -4): the
  // axes' nearest points are (0, 0, -4) and (0, 10, -4).
  const Geom cap{GeomKind::capsule, 2, 20, {}};
  Pose a;
  a.t = {0, 0, 0};
  Pose b;
  const double r[9] = {0, 0, 1, 0, 1, 0, -1, 0, 0};  // z -> x
  for (int k = 0; k < 9; ++k) b.r[k] = r[k];
  b.t = {3, 10, -4};
  Vec3 ca, cb;
  closest_cores(cap, a, cap, b, ca, cb);
  check_vec(ca, {0, 0, -4}, 1e-9);
  check_vec(cb, {0, 10, -4}, 1e-9);
}
