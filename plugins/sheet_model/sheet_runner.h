// The sheet model as one loop step, independent of the plugin ABI (the plugin wrapper is a
// thin shell around this; tests drive it directly): observations and model edits in, a
// SheetState out. The observed key-points, predicted to the step's time, pull the model
// through the coupling of params().solver.coupling: zero-length springs (seed 001 Eq. 4) or
// key-point velocities (seed 000 Eqs. 1-4); target points (set_targets) are springs either way. A step that leaves the state non-finite is rolled back to the state it
// started from (positions, zero velocities, rest lengths, plastic elongations, stiffnesses,
// creases) and reported, never propagated. Everything is allocated in the constructor.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "core/port_types/depth_targets.h"
#include "core/port_types/keypoints.h"
#include "core/port_types/sheet_state.h"
#include "collision_world.h"
#include "keypoint_predictor.h"
#include "sheet_model.h"

namespace crease::sheet {

class SheetRunner {
 public:
  static constexpr int kMarkerIds = 1024;  // key-point id = marker_id * 5 + corner

  // With table_height_mm finite, the table plane z = table_height_mm is a collision shape.
  explicit SheetRunner(const SheetParams& params, double table_height_mm = 0.0);  // throws crease::ConfigError
  // Runs a given backend (tests inject faulty ones; the ODE backend).
  explicit SheetRunner(std::unique_ptr<SheetModel> model, double table_height_mm = 0.0);

  // Inputs (RT). Times are CLOCK_MONOTONIC ns.
  void observe_keypoints(const Keypoints& k) noexcept;
  void set_targets(const TargetPoints& t) noexcept;
  // The depth path's targets (point-to-plane springs, SheetModel::set_normal_targets), used by
  // every step until replaced or until they are kDepthMaxAgeS older than the step. A target on a
  // grid node that also had one in the previous set (at most kDepthMaxGapS before) moves on at
  // the velocity between the two, for at most kDepthMaxPredictS (depth frames come at a few Hz
  // to 30 Hz; the model steps at 60 Hz) when set_depth_prediction(true) (off by default: in real
  // loops a late set extrapolated for long overshoots; measured in the depth_tracking plugin test).
  // Each target on a grid node gets the observed surface's normal from its neighbours' targets
  // (NormalTarget::surface_normal).
  void set_depth_targets(const DepthTargets& t) noexcept;
  void set_depth_prediction(bool on) noexcept { depth_predict_ = on; }
  static constexpr double kDepthMaxAgeS = 1.5;
  static constexpr double kDepthMaxGapS = 0.5;
  static constexpr double kDepthMaxPredictS = 0.5;
  [[nodiscard]] int depth_targets_used() const noexcept { return depth_used_; }
  void apply(const SheetCreaseEvent& e) noexcept;
  void apply(const SheetMemorizeEvent& e) noexcept;
  void apply(const SheetResetEvent& e) noexcept;

  // Advances the model to now_ns (by dt_s) and writes the state. Returns false when the step
  // went non-finite and the state was rolled back (the caller reports degraded). RT.
  bool step_rt(double dt_s, std::int64_t now_ns, SheetState& out) noexcept;

  [[nodiscard]] SheetModel& model() noexcept { return *model_; }
  [[nodiscard]] Coupling coupling() const noexcept { return coupling_; }
  [[nodiscard]] std::uint32_t rollbacks() const noexcept { return rollbacks_; }

 private:
  void fill_state(std::int64_t now_ns, SheetState& out) noexcept;
  [[nodiscard]] double seconds(std::int64_t ns) const noexcept {
    return static_cast<double>(ns - epoch_ns_) * 1e-9;
  }

  CollisionWorld world_;
  std::unique_ptr<SheetModel> model_;
  KeypointPredictor predictor_;
  Coupling coupling_;
  std::vector<TargetPoint> predicted_;  // predictor output plus target_points, capacity fixed
  std::vector<KeypointObs> keypoint_obs_;  // the predicted key-points for set_keypoints
  std::vector<TargetPoint> external_;
  int n_external_ = 0;
  std::vector<NormalTarget> depth_;  // capacity DepthTargets::kCapacity
  std::vector<NormalTarget> depth_used_targets_;  // depth_ predicted to the step's time
  std::vector<std::int32_t> depth_node_;          // per target: its grid node, -1: none
  std::vector<std::int32_t> node_depth_;          // per node: its target in depth_, -1: none
  std::vector<Vec3> node_last_, node_vel_;         // per node: last depth target, its velocity
  std::vector<std::int64_t> node_last_ns_;         // per node: when (INT64_MIN: never)
  bool depth_predict_ = false;
  int n_depth_ = 0;
  std::int64_t depth_stamp_ns_ = 0;
  int depth_used_ = 0;
  std::vector<Vec3> last_good_, normals_;
  std::vector<double> strain_;
  std::int64_t epoch_ns_ = 0;
  bool have_epoch_ = false;
  std::uint64_t steps_ = 0;
  std::uint32_t rollbacks_ = 0;
  std::uint32_t observations_ = 0;
  // The last state's fit error; infinite when it saw nothing (the first frame that sees again
  // does not learn).
  double last_fit_mm_ = std::numeric_limits<double>::infinity();
  double fit_good_s_ = 0;  // how long the fit has been within solver.learn_fit_mm
};

}  // namespace crease::sheet
