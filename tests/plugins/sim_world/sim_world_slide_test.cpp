// Shifting the sheet by pressing and sliding: a pressed fingertip drags the sheet over the table
// only when its cover grips paper better than the table does (the right hand's rubber, 1.2,
// against paper on the table, 0.35; the left hand's fabric, 0.25, slides over the sheet), and
// the sheet stays where it was left when the finger lifts.
// Failing variants: frictionless fingers drag nothing; a frictionless table lets even the
// fabric finger drag the sheet, and lets it coast on after the finger has lifted.
// And back over the table's edge: the sheet overhanging the far edge (folding's shift, seed 000
// Fig. 7a) is dragged back over it, the paper sliding up over the edge's rounding; failing
// variant: a square edge, whose side face the hanging paper meets and sticks to.
#include <cmath>
#include <string>

#include "scene.h"

using namespace scene;

namespace {

constexpr double kTravelMm = 40.0;

struct Slide {
  double shift_mm = 0;       // the sheet's centroid along the pull (-y) while pressed and pulled
  double after_lift_mm = 0;  // how far it moved once the finger was off it
  double tangential_n = 0;   // the fingertip's friction while pulling
  double normal_n = 0;
};

// SIDE's index presses the sheet (8 mm past the first contact, 3 N m/rad), pulls 40 mm towards
// the robot at 20 mm/s, lifts 15 mm and moves back in the air.
Slide slide(robot::Side side, WorldParams p) {
  p.initial_stiffness_nm_per_rad = 3.0;
  const double sx = side == robot::Side::right ? 1.0 : -1.0;
  const Vec3 above{20 * sx, 40, 8};
  Rig rig(p, "ffpad", above, palm_forward_down(side, deg(30)), index_out(), side);
  const double zc = rig.descend_to_contact(0, 10.0, -2.0);
  rig.move({above.x, above.y, zc - 8}, 10.0, 0.3);
  Slide out;
  const Vec3 c0 = sheet_centroid(*rig.world);
  rig.move({above.x, above.y - kTravelMm / 2, zc - 8}, 20.0);
  out.tangential_n = rig.hand().tip[0].tangential_force_n;
  out.normal_n = rig.hand().tip[0].normal_force_n;
  rig.move({above.x, above.y - kTravelMm, zc - 8}, 20.0, 0.2);
  out.shift_mm = c0.y - sheet_centroid(*rig.world).y;
  rig.move({above.x, above.y - kTravelMm, zc + 15}, 20.0, 0.1);
  const Vec3 c1 = sheet_centroid(*rig.world);
  rig.move({above.x, above.y, zc + 15}, 20.0, 0.3);
  out.after_lift_mm = sheet::norm(sheet_centroid(*rig.world) - c1);
  return out;
}

void print(const std::string& tag, const Slide& s) {
  MESSAGE(tag << ": sheet shifted " << s.shift_mm << " mm of " << kTravelMm << " (normal " << s.normal_n
              << " N, friction " << s.tangential_n << " N), then moved " << s.after_lift_mm << " mm with the finger off");
}

bool drags(const Slide& s) { return s.shift_mm > 0.75 * kTravelMm; }
bool leaves(const Slide& s) { return std::fabs(s.shift_mm) < 1.0; }
bool stays_after_lift(const Slide& s) { return s.after_lift_mm < 0.5; }

}  // namespace

TEST_CASE("a pressed rubber fingertip drags the sheet, a fabric one slides over it; lifted, the sheet stays") {
  const Slide rubber = slide(robot::Side::right, nominal());
  const Slide fabric = slide(robot::Side::left, nominal());
  print("rubber (right)", rubber);
  print("fabric (left)", fabric);
  CHECK(drags(rubber));
  CHECK(stays_after_lift(rubber));
  CHECK(leaves(fabric));
  CHECK(stays_after_lift(fabric));
  // Kinetic friction of the fabric cover over the held sheet: mu N.
  CHECK(fabric.tangential_n == doctest::Approx(0.25 * fabric.normal_n).epsilon(0.05));

  WorldParams slippery_fingers = nominal();
  slippery_fingers.finger_friction = false;
  const Slide r0 = slide(robot::Side::right, slippery_fingers);
  print("rubber, frictionless fingers", r0);
  CHECK_FALSE(drags(r0));

  WorldParams slippery_table = nominal();
  slippery_table.table_friction = false;
  const Slide f0 = slide(robot::Side::left, slippery_table);
  print("fabric, frictionless table", f0);
  CHECK_FALSE(leaves(f0));
  const Slide r1 = slide(robot::Side::right, slippery_table);
  print("rubber, frictionless table", r1);
  CHECK_FALSE(stays_after_lift(r1));
}

TEST_CASE(
    "a sheet overhanging the table's edge is dragged back over it; over a square edge it sticks") {
  // The table's far edge 33.5 mm inside the sheet's (config/sim.yaml's overhang), the hanging
  // paper drooping ~20 mm.
  WorldParams over_edge = nominal();
  over_edge.table_extent_mm = {-WorldParams::kNoEdge, WorldParams::kNoEdge, -WorldParams::kNoEdge,
                               115.0};
  const Slide round = slide(robot::Side::right, over_edge);
  print("rubber, back over the rounded edge", round);
  CHECK(round.shift_mm > 0.5 * kTravelMm);
  CHECK(stays_after_lift(round));

  WorldParams square = over_edge;
  square.table_edge_radius_mm = 0.0;
  const Slide stuck = slide(robot::Side::right, square);
  print("rubber, back over a square edge", stuck);
  CHECK(stuck.shift_mm < 0.25 * kTravelMm);
}
