// crease-bench depth's closed loop: a scene (the sheet and the robot's shapes at a time) rendered
// to the depth cameras (config/depth_cameras) and to the five colour cameras (config/cameras),
// the depth path and the marker path feeding the sheet model, the model scored against the
// scene's truth. Used for the printed sheet of the fold script (markers alone, markers fused with
// depth) and for the world's fold by the hands (bench_depth_world.cpp: plain or printed).
#pragma once

#include <functional>
#include <vector>

#include "core/port_types/sheet_state.h"
#include "plugins/depth_tracking/depth_tracker.h"
#include "plugins/sheet_model/sheet_params.h"
#include "plugins/sim_world/scene/fold_script.h"
#include "plugins/sim_world/scene/shape_view.h"
#include "plugins/sim_world/scene/sheet_mesh.h"

namespace crease::bench {

// The model against the truth over the fold (mm, mean over the nodes, from the fold's start).
struct TrackingError {
  double mean_mm = 0, worst_mm = 0, end_mm = 0;
  double worst_s = 0;         // the scene's time of the worst frame
  int keypoint_sets = 0;      // marker frames observed (15 Hz)
  double keypoints_mean = 0;  // triangulated key-points per marker frame
  int depth_frames = 0;       // depth frames processed (30 Hz)
  double targets_mean = 0;    // depth targets per depth frame
};

// Both parts' pieces: the truth's nodes as the renderers' mesh, the half fold's crease as the
// sequence announces it, and the model's mean node distance to the truth (mm).
[[nodiscard]] vision::SheetMesh mesh_of(const sheet::SheetParams& sp,
                                        const std::vector<sheet::Vec3>& nodes);
[[nodiscard]] SheetCreaseEvent half_fold_crease(const sheet::SheetParams& sp);
[[nodiscard]] double mean_error_mm(const SheetState& s, const std::vector<sheet::Vec3>& truth);

// What the cameras see at a time and what the model is scored against.
struct SceneAt {
  vision::SheetMesh mesh;                  // the sheet as rendered (any grid)
  std::vector<sheet::Vec3> truth;          // where the model's nodes truly are (its grid, mm)
  std::vector<vision::SceneShape> shapes;  // the robot's shapes the cameras draw (occluders)
  // What the robot's own kinematics tells the model (the folding sequence's target_points: the
  // pinch's grasp point at the hand while it holds); empty: nothing.
  std::vector<TargetPoints::Point> robot_targets;
};
// Fills the scene at T_S (s); successive calls never go back in time.
using SceneFeed = std::function<void(double t_s, SceneAt& out)>;

// The fold script's sheet (the model's own grid), no robot. SCRIPT is kept by reference.
[[nodiscard]] SceneFeed script_feed(const sheet::FoldScript& script, const sheet::SheetParams& sp,
                                    double start_s);

struct LoopSetup {
  sheet::SheetParams sheet;  // the model (origin, springs)
  SceneFeed scene;
  double crease_s =
      0.5;  // the fold starts: its crease announced (as the sequence does), scored from here
  bool announce_crease = true;
  bool robot_targets = true;  // the scene's robot_targets to the model (as target_points)
  double end_s = 7.0;
  depth::TrackerParams depth;  // the depth path's; its mask set here for the sheet's print
  bool printed = true;         // the printed sheet (config/markers/layout.yaml), else plain colour
  bool trace = false;          // a line every 0.5 s: the error, of the flap (v < half) and the rest
};

// One closed-loop run: depth targets at 30 Hz when use_depth, the five colour cameras' key-points
// (rendered, detected, triangulated; printed sheets only) at 15 Hz when use_markers; two 1/60 s
// model steps per 30 Hz frame, no loop latency. Rendering is not timed.
[[nodiscard]] TrackingError track_sheet(const LoopSetup& s, bool use_depth, bool use_markers);

}  // namespace crease::bench
