// Shifting the sheet by pressing and sliding: a pressed fingertip drags the sheet over the table
// only when its cover grips paper better than the table does (the right hand's rubber, 1.2,
// against paper on the table, 0.35; the left hand's fabric, 0.25, slides over the sheet), and
// the sheet stays where it was left when the finger lifts.
// Failing variants: frictionless fingers drag nothing; a frictionless table lets even the
// fabric finger drag the sheet, and lets it coast on after the finger has lifted.
// And back over the table's edge: the sheet overhanging the far edge (folding's shift, seed 000
// Fig. 7a) is dragged back over it, the paper sliding up over the edge's rounding; failing
// variant: a square edge, whose side face the hanging paper meets and sticks to.
// And on the sheet folded flat: the layers hold each other under the finger's press (fabric
// slides over the top layer, rubber drags the stack); failing variant: frictionless layers.
#include <cmath>
#include <string>
#include <vector>

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

// The sheet folded flat (the far half laid over the near half, one thickness apart, the crease's
// first link a chord), held so for 1 s and let go: SIDE's index presses the top layer 110 mm
// inside the crease as slide() presses and pushes it 40 mm towards the crease, the fingertips
// leading. How far the top layer's and the bottom layer's nodes nearest under the finger's
// start moved.
struct StackSlide {
  double top_mm = 0, bottom_mm = 0;
};
StackSlide slide_on_stack(robot::Side side, WorldParams p) {
  p.initial_stiffness_nm_per_rad = 3.0;
  const double sx = side == robot::Side::right ? 1.0 : -1.0;
  const Vec3 above{20 * sx, -110, 12};
  Rig rig(p, "ffpad", above, palm_forward_down(side, deg(30)), index_out(), side);
  auto& sheet = rig.world->sheet();
  const sheet::Grid& g = sheet.grid();
  std::vector<Vec3> x(sheet.positions().begin(), sheet.positions().end());
  constexpr int kCrease = 20;  // y = 0
  const double t = p.sheet.grid.thickness_mm;
  for (int j = 0; j < kCrease; ++j)
    for (int i = 0; i < g.w; ++i) {
      Vec3& q = x[g.index(i, j)];
      q.y = -(std::sqrt(g.dv * g.dv - t * t) + (kCrease - 1 - j) * g.dv);
      q.z += t;
    }
  sheet.set_positions(x);
  // Held so for 1 s, the crease's links yielding (world_params_test: kept at 155 deg).
  for (int k = 0; k < sheet.node_count(); ++k) sheet.pin(k, x[k]);
  rig.hold(1.0);
  for (int k = 0; k < sheet.node_count(); ++k) sheet.unpin(k);
  rig.hold(0.5);
  auto nearest_in = [&](int j0, int j1) {
    int best = -1;
    for (int j = j0; j <= j1; ++j)
      for (int i = 0; i < g.w; ++i)
        if (best < 0 || std::hypot(x[g.index(i, j)].x - above.x, x[g.index(i, j)].y - above.y) <
                            std::hypot(x[best].x - above.x, x[best].y - above.y))
          best = g.index(i, j);
    return best;
  };
  const int top = nearest_in(0, kCrease - 1), bottom = nearest_in(kCrease + 1, g.h - 1);
  const double zc = rig.descend_to_contact(0, 10.0, -2.0);
  rig.move({above.x, above.y, zc - 8}, 10.0, 0.3);
  const Vec3 top0 = sheet.positions()[top], bottom0 = sheet.positions()[bottom];
  rig.move({above.x, above.y + kTravelMm, zc - 8}, 20.0, 0.2);
  const Vec3 top1 = sheet.positions()[top], bottom1 = sheet.positions()[bottom];
  return {std::hypot(top1.x - top0.x, top1.y - top0.y),
          std::hypot(bottom1.x - bottom0.x, bottom1.y - bottom0.y)};
}

void print(const std::string& tag, const StackSlide& s) {
  MESSAGE(tag << ": the top layer moved " << s.top_mm << " mm, the bottom layer " << s.bottom_mm
              << " mm, of " << kTravelMm);
}

}  // namespace

TEST_CASE(
    "on a folded sheet a fabric fingertip slides over the top layer, a rubber one drags the stack; "
    "paper-paper friction holds the layers") {
  // The finger presses the top layer onto the bottom one lying on the table, and the layers
  // hold each other by paper-paper friction (0.4) under the finger's whole press
  // (finger_contacts.h, "a layer under the node"), the bottom one the table (0.35). Fabric (0.25)
  // slides over the top layer; rubber (1.2) drags it, and the bottom layer under it with it (0.4
  // beats 0.35). Failing variant: layers without friction, where fabric drags the top layer
  // (towards the crease, which pushes the bottom layer along through the fold).
  const StackSlide fabric = slide_on_stack(robot::Side::left, nominal());
  print("fabric on the stack", fabric);
  CHECK(fabric.top_mm < 3.0);
  CHECK(fabric.bottom_mm < 3.0);
  const StackSlide rubber = slide_on_stack(robot::Side::right, nominal());
  print("rubber on the stack", rubber);
  CHECK(rubber.top_mm > 0.75 * kTravelMm);
  CHECK(rubber.bottom_mm > 0.75 * kTravelMm);

  WorldParams slippery_layers = nominal();
  slippery_layers.layer_friction = false;
  const StackSlide f0 = slide_on_stack(robot::Side::left, slippery_layers);
  print("fabric on the stack, frictionless layers", f0);
  CHECK(f0.top_mm > 0.5 * kTravelMm);
}

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
