// The world's sheet (default_world_sheet) keeps a pressed crease and lets a loose fold spring
// back: A4 folded in half along its short axis (the near half over the far one), held in shape
// for 1 s (every node pinned: an idealised press of the whole fold), then released onto the
// table. Figure: the fold's angle at the crease 3 s after the release (180 deg: flat folded, 0:
// open), between the sheet's mean directions 4 rows (30 mm) to either side of the crease row.
// Issue 14 scores a fold as creased at >= 150 deg.
// Failing variants: no plasticity (the elastic sheet opens to where gravity holds it), and
// seed 001's rule at the previous rate 0.3 (its kinematic hardening springs back).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "plugins/sheet_model/collision_world.h"
#include "plugins/sheet_model/xpbd_sheet.h"
#include "plugins/sim_world/world_params.h"

using namespace crease::sheet;

namespace {

constexpr int kCreaseRow = 20;  // v = 148.5 mm: y = 0 when flat

double crease_angle_deg(const XpbdSheet& s) {
  const Grid& g = s.grid();
  const auto x = s.positions();
  auto row = [&](int j) {
    Vec3 c;
    for (int i = 0; i < g.w; ++i) c += x[g.index(i, j)];
    return (1.0 / g.w) * c;
  };
  const Vec3 a = row(kCreaseRow - 4) - row(kCreaseRow), b = row(kCreaseRow + 4) - row(kCreaseRow);
  const double c = dot(a, b) / (norm(a) * norm(b));
  return 180.0 - std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

struct Fold {
  double held_deg = 0, retained_deg = 0;
};

// The near half laid over the far half round a half loop of radius R_MM (0.5: the two layers
// one sheet thickness apart, a pressed crease, its first link across a chord), held 1 s,
// released for 3 s.
Fold fold_and_release(SheetParams p, double r_mm) {
  p.solver.friction = 0.35;  // paper on the table (config/robot/crease_robot.yaml)
  CollisionWorld table;
  table.add_table(0.0);
  XpbdSheet s(p);
  s.set_collision_world(&table);
  const Grid& g = s.grid();
  std::vector<Vec3> x(s.positions().begin(), s.positions().end());
  const double z0 = x[0].z;
  for (int j = kCreaseRow + 1; j < g.h; ++j)
    for (int i = 0; i < g.w; ++i) {
      Vec3& q = x[g.index(i, j)];
      const double arc = (j - kCreaseRow) * g.dv;
      if (std::numbers::pi * r_mm < g.dv) {  // tighter than a link: its first link a chord up
        q.y = std::sqrt(g.dv * g.dv - 4.0 * r_mm * r_mm) + (j - kCreaseRow - 1) * g.dv;
        q.z = z0 + 2.0 * r_mm;
      } else if (arc <= std::numbers::pi * r_mm) {
        q.y = -r_mm * std::sin(arc / r_mm);
        q.z = z0 + r_mm - r_mm * std::cos(arc / r_mm);
      } else {
        q.y = arc - std::numbers::pi * r_mm;
        q.z = z0 + 2.0 * r_mm;
      }
    }
  s.set_positions(x);
  for (int k = 0; k < s.node_count(); ++k) s.pin(k, x[k]);
  for (int n = 0; n < 1000; ++n) s.step_rt(0.001);
  Fold out;
  out.held_deg = crease_angle_deg(s);
  for (int k = 0; k < s.node_count(); ++k) s.unpin(k);
  for (int n = 0; n < 3000; ++n) s.step_rt(0.001);
  out.retained_deg = crease_angle_deg(s);
  REQUIRE(s.state_finite());
  return out;
}

}  // namespace

TEST_CASE("the world's sheet keeps a pressed crease, a loose fold springs back; without plasticity both open") {
  const SheetParams world = crease::world::default_world_sheet();
  const Fold creased = fold_and_release(world, 0.5);
  const Fold loose = fold_and_release(world, 20.0);
  MESSAGE("pressed crease: " << creased.held_deg << " deg held, " << creased.retained_deg << " deg 3 s after the release");
  MESSAGE("loose fold (a 40 mm loop): " << loose.held_deg << " deg held, " << loose.retained_deg << " deg after");
  CHECK(creased.retained_deg >= 150.0);
  CHECK(loose.retained_deg < 0.5 * loose.held_deg);

  SheetParams elastic = world;
  elastic.solver.plasticity_rate = 0.0;
  const Fold open = fold_and_release(elastic, 0.5);
  MESSAGE("pressed crease without plasticity: " << open.retained_deg << " deg after");
  CHECK(open.retained_deg < 90.0);

  SheetParams hardening = world;
  hardening.solver.plasticity_rate = 0.3;
  const Fold springy = fold_and_release(hardening, 0.5);
  MESSAGE("pressed crease at plasticity rate 0.3: " << springy.retained_deg << " deg after");
  CHECK(springy.retained_deg < 90.0);
}
