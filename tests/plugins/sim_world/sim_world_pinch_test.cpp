// A pinch of the sheet's corner between the right thumb and index holds it by friction: the
// corner hangs 48.5 mm over the table's near edge; the index, curled with its pad up, goes
// under it, the thumb closes on it from above, and the hand lifts 50 mm at 5 mm/s and pulls
// 60 mm away at 20 mm/s. The pinched sheet point goes with the pads.
// Failing variant: frictionless fingers: the sheet slides out of the same pinch.
// With the paper's strain limit (world param max_strain 0.01, off by default) the sheet keeps its
// length where the pinch holds, lifts and drags it; failing variant: without it the edges by the
// pinch stretch several times as far (one link pass per substep against the pads' friction).
#include <algorithm>
#include <cmath>
#include <string>

#include "plugins/sim_world/reference_poses.h"
#include "scene.h"

using namespace scene;

namespace {

// The pinch (plugins/sim_world/reference_poses.h): THJ5 0.3 open, 0.696 pads 4 mm apart.
using crease::world::poses::pinch_hand;

// The palm hanging down, the thumb pad facing straight down onto the index pad (reference_poses.h).
KDL::Rotation pinch_palm(const HandQ& h) { return crease::world::poses::pinch_palm(robot_model(), h); }

struct Pinch {
  double force_n = 0;  // squeeze between the pads once closed
  double rise_mm = 0;  // of the pinched sheet point over the 50 mm lift
  double slip_mm = 0;  // of that point relative to the index pad, over the lift and the pull
  double stretch[3] = {};  // the grid's largest edge stretch: closed, lifted, pulled
  double released = 0;     // ... 0.5 s after the thumb opened and the hand went up
};

Pinch pinch(WorldParams p) {
  p.table_extent_mm = {-WorldParams::kNoEdge, WorldParams::kNoEdge, -95.0, WorldParams::kNoEdge};
  p.initial_stiffness_nm_per_rad = 1.0;
  const Vec3 at{87, -134, -8};  // 18 mm inside the sheet's right edge, 14.5 mm inside its near edge
  Rig rig(p, "ffpad", at, pinch_palm(pinch_hand(0.696)), pinch_hand(0.3));
  rig.hold(0.3);                                // the overhang settles
  rig.move({at.x, at.y, -1.2}, 10.0, 0.1);      // the index pad under it
  for (int i = 1; i <= 500; ++i) {              // the thumb closes in 0.4 s, 0.1 s more to settle
    rig.hand_q[THJ5] = 0.3 + (0.77 - 0.3) * std::min(1.0, i / 400.0);
    rig.step_to(rig.last);
  }
  Pinch out;
  out.force_n = rig.hand().tip[0].normal_force_n;
  out.stretch[0] = max_edge_stretch(*rig.world);
  const auto x = rig.world->sheet().positions();
  int node = 0;
  for (int i = 1; i < rig.world->sheet().node_count(); ++i)
    if (sheet::norm(x[i] - Vec3{at.x, at.y, 0}) < sheet::norm(x[node] - Vec3{at.x, at.y, 0})) node = i;
  auto pad = [&] {
    const float* p3 = rig.hand().tip[0].position_mm;
    return Vec3{p3[0], p3[1], p3[2]};
  };
  const Vec3 z0 = rig.world->sheet().positions()[node];
  const Vec3 rel0 = z0 - pad();
  rig.move({at.x, at.y, 48.8}, 5.0, 0.2);
  out.rise_mm = rig.world->sheet().positions()[node].z - z0.z;
  out.stretch[1] = max_edge_stretch(*rig.world);
  rig.move({at.x, at.y - 60, 48.8}, 20.0, 0.3);
  out.stretch[2] = max_edge_stretch(*rig.world);
  out.slip_mm = sheet::norm((rig.world->sheet().positions()[node] - pad()) - rel0);
  for (int i = 1; i <= 300; ++i) {  // the thumb opens in 0.2 s
    rig.hand_q[THJ5] = 0.77 - 0.77 * std::min(1.0, i / 200.0);
    rig.step_to(rig.last);
  }
  rig.move({at.x, at.y - 60, 120}, 50.0, 0.5);
  out.released = max_edge_stretch(*rig.world);
  return out;
}

void print(const std::string& tag, const Pinch& p) {
  MESSAGE(tag << ": pinch " << p.force_n << " N; the pinched point rose " << p.rise_mm
              << " mm of 50, slipped " << p.slip_mm
              << " mm over the lift and a 60 mm pull; largest edge stretch " << 100 * p.stretch[0]
              << " / " << 100 * p.stretch[1] << " / " << 100 * p.stretch[2]
              << " % (closed / lifted / pulled), " << 100 * p.released << " % let go");
}

// Held: the point rose with the hand and did not slip by the pads' length (18 mm; a lost sheet
// falls away by ~100 mm).
bool holds(const Pinch& p) { return p.rise_mm > 40.0 && p.slip_mm < 18.0; }

}  // namespace

TEST_CASE("a pinch of a corner between thumb and index holds it by friction; frictionless it slips out") {
  const Pinch held = pinch(nominal());
  print("pinch", held);
  CHECK(held.force_n > 0.1);
  CHECK(holds(held));

  WorldParams slippery = nominal();
  slippery.finger_friction = false;
  const Pinch lost = pinch(slippery);
  print("frictionless fingers", lost);
  CHECK_FALSE(holds(lost));
}

TEST_CASE(
    "with the strain limit the pinched sheet keeps its length; without it the edges by the pinch "
    "stretch") {
  WorldParams limited = nominal();
  limited.sheet.solver.max_strain = 0.01;
  const Pinch held = pinch(limited);
  print("strain limit 1 %", held);
  for (const double s : held.stretch)
    CHECK(s < 0.025);          // 1 % per link; the tethered holds, the sweeps' rest
  CHECK(held.rise_mm > 40.0);  // lifted with the hand
  // (Let go, 2.6 % remains, 3.3 % without the limit: the bending links' set in tension.)

  const Pinch loose = pinch(nominal());
  print("no strain limit", loose);
  CHECK(loose.stretch[1] > 0.05);  // lifted
  CHECK(loose.stretch[2] > 0.05);  // pulled
}
