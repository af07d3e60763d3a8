// The thumb against the other fingers (thumb_contacts.h): a pinch closed past touching with
// nothing between the pads stops at the index; both pads feel the squeeze, equal and opposite;
// the thumb's joints deflect. Failing variant: without the contacts the thumb sinks into the
// index pad and neither feels a thing.
// And the figure that made it: the fold's pinch (sim_world_fold_test) no longer reads 30-200 N
// on a fingertip for a step when a node of the sheet slips between the overlapping pads.
#include "plugins/sim_world/thumb_contacts.h"

#include <doctest/doctest.h>

#include <cmath>

#include "plugins/sim_world/reference_poses.h"
#include "scene.h"

using namespace scene;

namespace {

struct Closed {
  double overlap_mm =
      0;  // how far the index and thumb pads' covers overlap (cores' radii less their distance)
  double ff_n = 0, th_n = 0;
  double thj5_deflection_rad = 0;
};

// The right hand 100 mm over the table, away from the sheet, closes the pinch (THJ5 0.3 -> 0.77;
// 0.696 touches) at 3 N m/rad.
Closed close_pinch(WorldParams p) {
  p.initial_stiffness_nm_per_rad = 3.0;
  const Vec3 at{0, -250, 100};
  Rig rig(p, "ffpad", at,
          crease::world::poses::pinch_palm(robot_model(), crease::world::poses::pinch_hand(0.696)),
          crease::world::poses::pinch_hand(0.3));
  for (int i = 1; i <= 600; ++i) {
    rig.hand_q[THJ5] = 0.3 + (0.77 - 0.3) * std::min(1.0, i / 400.0);
    rig.step_to(rig.last);
  }
  Closed out;
  const auto& shapes = rig.world->shapes();
  int ff = -1, th = -1;
  for (int k = 0; k < static_cast<int>(shapes.size()); ++k) {
    if (shapes[k].side != 0 || shapes[k].role != crease::world::ShapeRole::pad) continue;
    if (shapes[k].fingertip == 0) ff = k;
    if (shapes[k].fingertip == 4) th = k;
  }
  REQUIRE(ff >= 0);
  REQUIRE(th >= 0);
  const auto &a = shapes[ff], &b = shapes[th];
  Vec3 ca, cb;
  crease::world::closest_cores(a.geom, a.pose1, b.geom, b.pose1, ca, cb, 8);
  out.overlap_mm =
      crease::world::core_grow(a.geom) + crease::world::core_grow(b.geom) - sheet::norm(cb - ca);
  out.ff_n = rig.hand().tip[0].normal_force_n;
  out.th_n = rig.hand().tip[4].normal_force_n;
  out.thj5_deflection_rad = rig.hand().deflection_rad[THJ5];
  return out;
}

}  // namespace

TEST_CASE("a pinch closed past touching stops at the index: both pads feel it, the thumb yields") {
  const Closed c = close_pinch(nominal());
  MESSAGE("thumb contacts: pads overlap " << c.overlap_mm << " mm, ff " << c.ff_n << " N, th "
                                          << c.th_n << " N, THJ5 deflected "
                                          << c.thj5_deflection_rad << " rad");
  CHECK(c.overlap_mm < 0.5);
  CHECK(c.ff_n > 0.2);
  CHECK(c.th_n == doctest::Approx(c.ff_n).epsilon(0.05));
  CHECK(c.thj5_deflection_rad < -0.005);  // held back from its target

  WorldParams off = nominal();
  off.thumb_contacts = false;
  const Closed d = close_pinch(off);
  MESSAGE("without: pads overlap " << d.overlap_mm << " mm, ff " << d.ff_n << " N, th " << d.th_n
                                   << " N");
  CHECK_FALSE(d.overlap_mm < 0.5);
  CHECK(d.ff_n < 0.01);
}
