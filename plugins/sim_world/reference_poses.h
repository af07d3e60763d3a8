// Hand postures the world's scenes share (its tests, crease-bench world): rad, drivers/README.md
// §3 order. Found on this robot's URDF, not calibrated on the real hands.
#pragma once

#include <array>
#include <numbers>

#include "plugins/robot_model/robot_layout.h"

namespace crease::world::poses {

using HandQ = std::array<double, robot::kHandJoints>;

// Hand joint indices (drivers/README.md §3).
enum HandJoint { WRJ2, WRJ1, FFJ4, FFJ3, FFJ2, MFJ4, MFJ3, MFJ2, RFJ4, RFJ3, RFJ2, LFJ5, LFJ4, LFJ3, LFJ2,
                 THJ5, THJ4, THJ3, THJ2, THJ1 };

// Only the index finger out: the others bent back to their J3 limit (-15 deg).
inline HandQ index_out() {
  HandQ h{};
  h[MFJ3] = h[RFJ3] = h[LFJ3] = -15.0 * std::numbers::pi / 180.0;
  return h;
}

// The thumb-index pinch found by a search over the index's and thumb's joints: the index curled
// pad up, the pads facing 4 mm apart at THJ5 0.696; THJ5 opens (0.3) and closes it (0.77 squeezes).
inline HandQ pinch_hand(double thj5) {
  HandQ h = index_out();
  h[FFJ4] = 0.201;
  h[FFJ3] = 1.428;
  h[FFJ2] = 0.321;
  h[THJ5] = thj5;
  h[THJ4] = 1.072;
  h[THJ3] = 0.027;
  h[THJ2] = -0.549;
  h[THJ1] = -0.117;
  return h;
}

}  // namespace crease::world::poses
