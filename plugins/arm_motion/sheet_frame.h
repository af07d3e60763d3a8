// The sheet frame a goal's points may be given in (ArmGoal::sheet), from a sheet_state: origin at
// node (0, 0) (u = v = 0), x towards node (W-1, 0) (along u), z = x cross (node (0, (H-1)/4) -
// origin) (DESIGN's z = u x v: into the paper, away from the printed face), y = z cross x. A
// rigid frame of the sheet's edges at the origin: what a fold's points are relative to when the
// motion starts. A quarter along the v edge, not its far corner: that corner is what the half
// fold lifts and carries over (its frame turned with the bend, and the bend's next via point was
// out of reach); nor halfway, on the half fold's crease, which a fold lifts into a loop (a loop
// 30 mm tall there tilted the frame so that a descent 5 mm into the stack 40 mm from the near
// edge ended 3 mm over it: no contact). The half fold's and the diagonal fold's bases keep that
// node where it lay.
// RT: reads three nodes.
#pragma once

#include <kdl/frames.hpp>

#include "core/port_types/sheet_state.h"

namespace crease::arm_motion {

// World <- sheet, metres. False for a state with fewer than 2 x 2 nodes, non-finite corner
// nodes or degenerate (coincident or collinear) edges.
[[nodiscard]] bool sheet_frame_m(const SheetState& s, KDL::Frame& world_sheet) noexcept;

}  // namespace crease::arm_motion
