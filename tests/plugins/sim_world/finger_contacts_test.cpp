// The fingers' contacts on small sheets with shapes written inline: a node pressed onto the
// table carries what the cover's compression says whatever its mass (the exact block solve), a
// node pinched between two equal covers sits between them with equal loads, a tilted face
// presses the sheet down without squeezing it out sideways, and the residuals list the gap of
// a contact about to close.
#include "plugins/sim_world/finger_contacts.h"

#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "plugins/sheet_model/collision_world.h"
#include "plugins/sheet_model/xpbd_sheet.h"
#include "rt/alloc_guard.h"

using namespace crease;
using namespace crease::world;

namespace {

// A 5 x 5 sheet of 40 mm on the table (nodes 10 mm apart, centre node 12 at (20, -20)).
sheet::SheetParams small_sheet(double grammage) {
  sheet::SheetParams p;
  p.grid.nodes_u = 5;
  p.grid.nodes_v = 5;
  p.grid.width_mm = 40;
  p.grid.height_mm = 40;
  p.grid.areal_density_g_per_m2 = grammage;
  p.grid.origin_mm = {0, 0, 0.5};
  p.solver.substeps = 2;
  return p;
}

// A shape on its own body (two of them pinch; one body's shapes never do).
WorldShape sphere_at(Vec3 c, double r, double mu, double k_area, int body = 0) {
  WorldShape s;
  s.body = body;
  s.finger = body;
  s.geom = {GeomKind::sphere, r, 0.0, {}};
  s.pose0.t = s.pose1.t = c;
  s.friction = mu;
  s.stiffness_n_per_mm3 = k_area;
  s.compliant = true;
  return s;
}

struct Bench {
  Bench(const sheet::SheetParams& p, std::vector<WorldShape> shapes_) : sheet(p), shapes(std::move(shapes_)) {
    table.add_table(0.0);
    sheet.set_collision_world(&table);
    FingerContacts::Config cfg;
    fc.configure(sheet, shapes, cfg);
    sheet.set_substep_contacts(&fc);
  }
  void step() {
    for (WorldShape& s : shapes) s.pose0 = s.pose1;
    fc.begin_step_rt(sheet.positions(), sheet.velocities(), 0.001);
    sheet.step_rt(0.001);
    fc.end_step_rt(sheet.positions());
  }
  sheet::XpbdSheet sheet;
  sheet::CollisionWorld table;
  std::vector<WorldShape> shapes;
  FingerContacts fc;
};

}  // namespace

TEST_CASE("a node pressed onto the table carries the cover's compression times its stiffness, whatever its mass") {
  double force[2];
  for (int m = 0; m < 2; ++m) {
    // A sphere of radius 5 whose bottom is 0.2 mm into the centre node's top surface (at 1 mm).
    Bench b(small_sheet(m == 0 ? 80.0 : 800.0), {sphere_at({20, -20, 5.8}, 5.0, 0.0, 0.5)});
    for (int i = 0; i < 20; ++i) b.step();
    CHECK(b.sheet.positions()[12].z == doctest::Approx(0.5).epsilon(1e-6));  // held by the table
    const auto res = b.fc.residuals();
    double depth = 0, k = 0;
    for (const auto& r : res)
      if (r.depth_mm > 0) {
        depth = r.depth_mm;
        k = r.stiffness_n_per_mm;
      }
    CHECK(depth == doctest::Approx(0.2).epsilon(1e-3));
    CHECK(k == doctest::Approx(0.5 * 100.0));  // 0.5 N/mm^3 over the node's 10 x 10 mm
    force[m] = b.fc.load(0).normal_n.z;
    CHECK(force[m] == doctest::Approx(k * depth).epsilon(1e-3));  // the shape is pushed up
  }
  CHECK(force[1] == doctest::Approx(force[0]).epsilon(1e-3));
}

TEST_CASE("a node pinched between two equal covers sits between them, loaded equally") {
  sheet::SheetParams p = small_sheet(80.0);
  p.solver.gravity_mm_per_s2 = {0, 0, 0};
  p.grid.origin_mm.z = 20.0;  // off the table
  // Spheres above and below the centre node (at z 20), each 0.3 mm into its surface.
  Bench b(p, {sphere_at({20, -20, 20 + 0.5 + 5 - 0.3}, 5.0, 0.0, 0.5, 0), sphere_at({20, -20, 20 - 0.5 - 5 + 0.3}, 5.0, 0.0, 0.5, 1)});
  b.step();
  CHECK(b.sheet.positions()[12].z == doctest::Approx(20.0).epsilon(1e-6));
  const double up = b.fc.load(0).normal_n.z, down = b.fc.load(1).normal_n.z;
  CHECK(up > 0.0);  // the upper shape is pushed up
  CHECK(down == doctest::Approx(-up).epsilon(1e-6));
  CHECK(up == doctest::Approx(50.0 * 0.3).epsilon(1e-2));
  // The hands' balance sees one pinch: both shapes, both depths, the covers in series.
  const auto res = b.fc.residuals();
  REQUIRE(res.size() >= 1);
  bool pinch = false;
  for (const auto& r : res)
    pinch = pinch || (r.shape2 >= 0 && r.depth_mm == doctest::Approx(0.6).epsilon(1e-2) && r.stiffness_n_per_mm == doctest::Approx(25.0));
  CHECK(pinch);
}

TEST_CASE("one body's shapes (a fingertip's cover and pad) never pinch a node between them") {
  sheet::SheetParams p = small_sheet(80.0);
  p.solver.gravity_mm_per_s2 = {0, 0, 0};
  p.grid.origin_mm.z = 20.0;
  Bench b(p, {sphere_at({20, -20, 20 + 0.5 + 5 - 0.3}, 5.0, 0.0, 0.5, 3), sphere_at({20, -20, 20 - 0.5 - 5 + 0.3}, 5.0, 0.0, 0.5, 3)});
  b.step();
  CHECK(b.fc.residuals().empty());  // the same spheres on two bodies make a pinch (above)
}

TEST_CASE("a tilted face presses the sheet down; it does not squeeze it out sideways") {
  // A box pad turned 30 deg about x, its face 0.2 mm into the nodes' surface, no friction.
  WorldShape pad;
  pad.geom = {GeomKind::box, 0, 0, {9, 7, 1}};
  const double a = 0.5235987755982988, c = std::cos(a), s = std::sin(a);
  const double r[9] = {1, 0, 0, 0, c, -s, 0, s, c};
  for (int k = 0; k < 9; ++k) pad.pose1.r[k] = r[k];
  pad.pose1.t = {20, -20, 1.0 + 1.0 / c - 0.2};
  pad.pose0 = pad.pose1;
  pad.stiffness_n_per_mm3 = 0.5;
  pad.compliant = true;
  Bench b(small_sheet(80.0), {pad});
  const Vec3 before = b.sheet.positions()[12];
  for (int i = 0; i < 50; ++i) b.step();
  const Vec3 after = b.sheet.positions()[12];
  CHECK(std::fabs(after.y - before.y) < 1e-6);
  CHECK(after.z == doctest::Approx(0.5).epsilon(1e-6));
  CHECK(b.fc.load(0).normal_n.z > 0.0);
  CHECK(std::fabs(b.fc.load(0).normal_n.y) < 1e-9);
}

TEST_CASE("residuals list the gap of a contact about to close; a step allocates nothing") {
  Bench b(small_sheet(80.0), {sphere_at({20, -20, 7.0}, 5.0, 0.0, 0.5)});  // 1 mm above the sheet
  b.step();
  CHECK(b.fc.residuals().empty());  // the step's end lists what presses only
  const Pose at[1] = {b.shapes[0].pose1};
  b.fc.measure_rt(at, b.sheet.positions());  // what the hands' balance asks for: the gaps too
  bool gap = false;
  for (const auto& r : b.fc.residuals()) gap = gap || (r.depth_mm < 0 && r.depth_mm > -1.5);
  CHECK(gap);
  CHECK(b.fc.load(0).nodes == 0);
  REQUIRE(rt::alloc_hooks_installed());
  const auto before = rt::rt_allocation_count();
  {
    rt::ScopedRtMark mark;
    for (int i = 0; i < 50; ++i) {
      b.shapes[0].pose1.t.z -= 0.05;
      b.step();
    }
  }
  CHECK(rt::rt_allocation_count() == before);
  CHECK(b.fc.load(0).nodes > 0);
}
