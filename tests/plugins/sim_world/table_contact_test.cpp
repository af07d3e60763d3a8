// A robot shape against the table slab (table_contact.h): under the top it is pushed out through
// the nearest face; a finger come in under the top from beyond an edge meets the edge's face,
// sideways and as deep as it is past that face, not 30 mm under the top; over the top a gap.
#include "plugins/sim_world/table_contact.h"

#include <doctest/doctest.h>

#include "plugins/sim_world/world_params.h"

using namespace crease::world;

namespace {

constexpr double kNo = WorldParams::kNoEdge;

Geom sphere(double r) {
  Geom g;
  g.kind = GeomKind::sphere;
  g.radius_mm = r;
  return g;
}

Pose at(double x, double y, double z) {
  Pose p;
  p.t = {x, y, z};
  return p;
}

}  // namespace

TEST_CASE(
    "a shape in under the top by the far edge is pushed out through the edge's face, sideways") {
  const double edge[4] = {-kNo, kNo, -kNo,
                          115.0};  // the simulated robot's table: its far edge at y = 115
  // A fingertip (10 mm) 20 mm under the top, its centre 5 mm inside the edge: 15 mm past the edge's
  // face.
  const TableContact c = table_contact(sphere(10), at(0, 110, -20), 0.0, edge);
  REQUIRE(c.over);
  CHECK(c.depth_mm == doctest::Approx(15.0));
  CHECK(c.normal.y == -1.0);  // the table pushes it out along +y
  CHECK(c.normal.z == 0.0);
  CHECK(c.point.y == doctest::Approx(100.0));
  // The same tip on an endless table top: under the top, 30 mm deep (what the edge's tip read
  // before).
  const double endless[4] = {-kNo, kNo, -kNo, kNo};
  const TableContact d = table_contact(sphere(10), at(0, 110, -20), 0.0, endless);
  CHECK(d.depth_mm == doctest::Approx(30.0));
  CHECK(d.normal.z == -1.0);
}

TEST_CASE(
    "pressed onto the top well inside the edges, the top is the nearest face; above it a gap; "
    "beyond an edge nothing") {
  const double edge[4] = {-200, 200, -150, 115.0};
  const TableContact pressed =
      table_contact(sphere(8), at(0, 0, 6), 0.0, edge);  // 2 mm into the top
  REQUIRE(pressed.over);
  CHECK(pressed.depth_mm == doctest::Approx(2.0));
  CHECK(pressed.normal.z == -1.0);
  CHECK(pressed.point.z == doctest::Approx(-2.0));
  const TableContact above = table_contact(sphere(8), at(0, 0, 20), 0.0, edge);
  CHECK(above.over);
  CHECK(above.depth_mm == doctest::Approx(-12.0));                         // the gap
  CHECK_FALSE(table_contact(sphere(8), at(0, 130, -20), 0.0, edge).over);  // beyond the far edge
  // Near a side edge but shallow under the top: the top is still the nearest (2 mm < 5 mm).
  const TableContact corner = table_contact(sphere(8), at(-195, 0, 6), 0.0, edge);
  CHECK(corner.normal.z == -1.0);
  CHECK(corner.depth_mm == doctest::Approx(2.0));
  // Deep by the left edge (x_min): pushed out along -x.
  const TableContact left = table_contact(sphere(8), at(-196, 0, -30), 0.0, edge);
  CHECK(left.normal.x == 1.0);
  CHECK(left.depth_mm == doctest::Approx(12.0));
}
