// The sheet model behind one interface: state that every backend shares (topology, rest
// lengths, per-link stiffness, creases, memorized shape, plastic elongation, observation
// inputs, pins) lives here; a backend (XPBD, ODE) implements the time step.
//
// Threading: configure-time calls (constructor) allocate; everything marked noexcept below
// is RT-safe (no allocation, no locks, no exceptions).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "creases.h"
#include "sheet_params.h"
#include "topology.h"
#include "vec3.h"

namespace crease::sheet {

class CollisionWorld;

// seed 000 IV.B: an observed world position k^w of sheet point k^m.
struct KeypointObs {
  Vec3 world_mm;
  Vec2 sheet_mm;
};

// seed 001 III.B: a zero-length spring from sheet point `sheet_mm` to `world_mm`.
struct TargetPoint {
  Vec3 world_mm;
  Vec2 sheet_mm;
};

// A depth target: sheet point `sheet_mm` pulled towards `world_mm` by a zero-length spring of
// stiffness scaled by `weight` (0, 1], along the model's normal at that point when the solver's
// depth_along_normal is set (the depth path: plugins/depth_tracking); with depth_surface_normal
// and a known `surface_normal`, along the bisector of the two.
struct NormalTarget {
  Vec3 world_mm;
  Vec2 sheet_mm;
  double weight = 1.0;
  Vec3 surface_normal{};  // unit normal of the observed surface there (zero: not known)
};

struct Region {
  Vec2 min, max;  // axis-aligned rectangle in sheet mm
};

// The four grid nodes around a sheet point, with bilinear weights (sum 1) and seed 000
// Eq. 2 influence factors alpha = max(1 - |k^m - n^m| (grid units), 0).
struct SheetPointStencil {
  std::array<std::int32_t, 4> node{};
  std::array<double, 4> bilinear{};
  std::array<double, 4> alpha{};
};

// A range [first, last) of a model's current inputs (targets or key-points).
struct InputRange {
  int first = 0, last = 0;
  [[nodiscard]] bool has(int i) const noexcept { return i >= first && i < last; }
};

class SheetModel {
 public:
  static constexpr int kMaxTargets = 4096;
  static constexpr int kMaxKeypoints = kMaxTargets;  // either coupling takes as many observations

  explicit SheetModel(const SheetParams& params);  // throws crease::ConfigError
  virtual ~SheetModel() = default;
  SheetModel(const SheetModel&) = delete;
  SheetModel& operator=(const SheetModel&) = delete;

  // Advances the model by dt_s with params().solver.substeps substeps. RT.
  virtual void step_rt(double dt_s) noexcept = 0;
  [[nodiscard]] virtual std::span<const Vec3> positions() const noexcept = 0;
  [[nodiscard]] virtual std::span<const Vec3> velocities() const noexcept = 0;
  // Sets every node's position (span of node_count()), zero velocity. RT.
  virtual void set_positions(std::span<const Vec3> pos) noexcept = 0;
  [[nodiscard]] virtual const char* backend_name() const noexcept = 0;

  // Flat sheet at the configured origin, no creases, rest lengths from the flat sheet. RT.
  void reset_rt() noexcept;

  // Creases (seed 000 III): links crossing the segment get crease_stiffness. RT.
  int add_crease(CreaseLine line) noexcept;  // id, or -1 when full
  bool remove_crease(int id) noexcept;
  [[nodiscard]] const CreaseSet& creases() const noexcept { return creases_; }
  // A crease inferred from the strain (solver.crease_strain > 0; the backends call it once per
  // frame): every bending link whose |strain| passes crease_strain takes crease_stiffness and
  // keeps it until reset_rt. Returns the links newly cut. RT.
  int infer_creases_rt() noexcept;
  // Whether the links learn this frame: the plastic update and infer_creases_rt (default on). RT.
  void set_links_learn(bool on) noexcept { links_learn_ = on; }
  [[nodiscard]] bool links_learn() const noexcept { return links_learn_; }
  [[nodiscard]] int inferred_crease_links() const noexcept { return n_inferred_; }

  // Memorize (seed 000): rest length := current length, permanent elongation := 0. RT.
  void memorize_all() noexcept;
  int memorize_region(Region r) noexcept;  // links with both ends in r; returns their count

  // Observation inputs, used by every substep until replaced. Non-finite entries are
  // dropped; returns the number accepted. RT.
  int set_keypoints(std::span<const KeypointObs> k) noexcept;
  int set_targets(std::span<const TargetPoint> t) noexcept;
  // Depth targets (non-finite entries and weights outside (0, 1] dropped). Only the XPBD
  // backend applies them (the ODE backend ignores them). RT.
  int set_normal_targets(std::span<const NormalTarget> t) noexcept;
  void set_keypoint_gain(double lambda_per_s) noexcept { keypoint_gain_ = lambda_per_s; }
  // Nodes that no target or key-point of the current inputs touches move no faster than this
  // (mm/s; <= 0 or not finite: no limit beyond solver.max_speed_mm_per_s). RT.
  // Inputs predicted through a gap rather than seen: targets [first, last) and key-points
  // [first, last) of the current inputs; the nodes only they touch count as unseen.
  void set_unseen_speed_limit(double mm_per_s, InputRange predicted_targets = {},
                              InputRange predicted_keypoints = {}) noexcept {
    unseen_speed_limit_ = mm_per_s;
    predicted_targets_ = predicted_targets;
    predicted_keypoints_ = predicted_keypoints;
  }
  void clear_inputs() noexcept {
    n_keypoints_ = 0;
    n_targets_ = 0;
    n_normal_targets_ = 0;
  }

  // A pinned node follows a prescribed position (infinite mass). RT.
  void pin(int node, Vec3 world_mm) noexcept;
  void unpin(int node) noexcept;

  // Rigid shapes and the table (optional, not owned; must outlive the model).
  void set_collision_world(const CollisionWorld* world) noexcept { world_ = world; }

  [[nodiscard]] const SheetParams& params() const noexcept { return params_; }
  [[nodiscard]] const Topology& topology() const noexcept { return topo_; }
  [[nodiscard]] const Grid& grid() const noexcept { return topo_.grid; }
  [[nodiscard]] int node_count() const noexcept { return topo_.grid.count(); }
  [[nodiscard]] int link_count() const noexcept { return topo_.link_count(); }
  [[nodiscard]] std::span<const double> rest_lengths() const noexcept { return rest_; }
  [[nodiscard]] std::span<const double> plastic_elongations() const noexcept { return plastic_; }
  [[nodiscard]] std::span<const double> stiffnesses() const noexcept { return stiffness_; }
  [[nodiscard]] std::span<const double> node_masses_kg() const noexcept { return mass_; }
  [[nodiscard]] Vec3 flat_position(Vec2 sheet) const noexcept;
  [[nodiscard]] SheetPointStencil stencil(Vec2 sheet) const noexcept;
  // World position of a sheet point, bilinear over the current positions. RT.
  [[nodiscard]] Vec3 interpolate(Vec2 sheet) const noexcept;
  // Unit normal of the printed face at every node (area-weighted over triangles). RT.
  void compute_normals(std::span<Vec3> out) const noexcept;
  // Per-link strain (|x_b - x_a| - rest) / rest. RT.
  void compute_strains(std::span<double> out) const noexcept;
  [[nodiscard]] bool state_finite() const noexcept;
  // Incremented whenever rest lengths, stiffnesses or the set of pinned nodes change
  // (backends re-read them).
  [[nodiscard]] std::uint64_t links_version() const noexcept { return links_version_; }

  // The link state (rest lengths, plastic elongations, stiffnesses, creases) kept for a
  // rollback: save_links_rt copies what changed since the last save (rest lengths,
  // stiffnesses and creases when links_version() moved; plastic elongations when a step
  // changed one); restore_links_rt puts the saved copy back
  // (backends re-read it). Positions are the caller's (set_positions). RT, no allocation.
  void save_links_rt() noexcept;
  void restore_links_rt() noexcept;

 protected:
  // The accepted key-points and their stencils (what the backends' KeypointCoupling reads).
  [[nodiscard]] std::span<const KeypointObs> keypoints() const noexcept {
    return {keypoints_.data(), static_cast<std::size_t>(n_keypoints_)};
  }
  [[nodiscard]] std::span<const SheetPointStencil> keypoint_stencils() const noexcept {
    return {keypoint_stencil_.data(), static_cast<std::size_t>(n_keypoints_)};
  }
  void restore_link_stiffness() noexcept;  // default stiffness, then every crease applied
  [[nodiscard]] double link_base_compliance(int link) const noexcept;

  SheetParams params_;
  Topology topo_;
  std::vector<double> mass_;        // kg per node (area-lumped)
  std::vector<Vec3> flat_;          // flat positions, mm
  std::vector<double> rest_;        // l, mm
  std::vector<double> plastic_;     // dl_p, mm
  std::vector<double> stiffness_;   // seed 000 coefficient s in (0, 1]
  std::vector<double> compliance_;  // alpha = base / s, m/N
  std::vector<std::uint8_t> pinned_;
  std::vector<Vec3> pin_pos_;
  CreaseSet creases_;
  std::vector<std::uint8_t> inferred_;  // per link: cut by infer_creases_rt
  int n_inferred_ = 0;
  std::vector<KeypointObs> keypoints_;  // capacity kMaxKeypoints
  std::vector<SheetPointStencil> keypoint_stencil_;
  int n_keypoints_ = 0;
  std::vector<TargetPoint> targets_;    // capacity kMaxTargets
  std::vector<SheetPointStencil> target_stencil_;
  int n_targets_ = 0;
  std::vector<NormalTarget> normal_targets_;  // capacity kMaxTargets
  std::vector<SheetPointStencil> normal_stencil_;
  int n_normal_targets_ = 0;
  double keypoint_gain_ = 10.0;
  double unseen_speed_limit_ = 0.0;  // mm/s, <= 0: none
  bool links_learn_ = true;
  InputRange predicted_targets_, predicted_keypoints_;  // predicted, not seen
  const CollisionWorld* world_ = nullptr;
  std::uint64_t links_version_ = 0;
  std::uint64_t plastic_version_ = 0;  // backends: +1 whenever a plastic elongation changed

 private:
  std::vector<double> saved_rest_, saved_plastic_, saved_stiffness_, saved_compliance_;
  std::vector<std::uint8_t> saved_inferred_;
  int saved_n_inferred_ = 0;
  CreaseSet saved_creases_;
  std::uint64_t saved_version_ = ~std::uint64_t{0};
  std::uint64_t saved_plastic_version_ = ~std::uint64_t{0};
};

}  // namespace crease::sheet
