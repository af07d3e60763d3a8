// crease-bench depth's second part: the printed sheet (config/markers/layout.yaml) tracked by
// the marker path alone and by the markers fused with the depth path (seed 001 with seed 000's
// key-points), in the same closed loop and the same half fold as the depth-only part.
#pragma once

#include <vector>

#include "core/port_types/sheet_state.h"
#include "plugins/depth_tracking/depth_tracker.h"
#include "plugins/sheet_model/sheet_params.h"
#include "plugins/sim_world/scene/fold_script.h"
#include "plugins/sim_world/scene/sheet_mesh.h"

namespace crease::bench {

// The model against the truth over the fold (mm, mean over the nodes, from the fold's start).
struct TrackingError {
  double mean_mm = 0, worst_mm = 0, end_mm = 0;
  int keypoint_sets = 0;      // marker frames observed (15 Hz)
  double keypoints_mean = 0;  // triangulated key-points per marker frame
};

// Both parts' pieces: the truth's nodes as the renderers' mesh, the half fold's crease as the
// sequence announces it, and the model's mean node distance to the truth (mm).
[[nodiscard]] vision::SheetMesh mesh_of(const sheet::SheetParams& sp,
                                        const std::vector<sheet::Vec3>& nodes);
[[nodiscard]] SheetCreaseEvent half_fold_crease(const sheet::SheetParams& sp);
[[nodiscard]] double mean_error_mm(const SheetState& s, const std::vector<sheet::Vec3>& truth);

struct FusedSetup {
  sheet::SheetParams sheet;  // the model (origin, springs) as the depth-only part
  const sheet::FoldScript* script = nullptr;
  double start_s = 0.5;  // the fold starts (and its crease is announced) here
  double end_s = 7.0;
  depth::TrackerParams depth;  // the depth path's, its mask set here for the printed sheet
};

// One closed-loop run: depth targets at 30 Hz when use_depth, the five colour cameras' key-points
// (rendered, detected, triangulated) at 15 Hz when use_markers. Rendering is not timed.
[[nodiscard]] TrackingError track_printed_sheet(const FusedSetup& s, bool use_depth,
                                                bool use_markers);

}  // namespace crease::bench
