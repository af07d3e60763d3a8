// The substep XPBD backend (seed 001 III.A-C, seed 000 IV.B coupling).
// One frame of dt: N_s substeps of dt_s = dt / N_s, each:
//   key-point velocities (seed 000 Eqs. 1-4) -> prediction (seed 001 Eq. 1) ->
//   links, Gauss-Seidel, one pass, lambda = 0 per substep (seed 001 Eqs. 2-3) ->
//   zero-length target springs (seed 001 Eq. 4) -> external substep contacts, if set
//   (substep_contacts.h: the world's fingers) -> strain limit (strain_limit.h,
//   solver.max_strain > 0 only; the external contacts' holds) -> contacts (table, shapes;
//   layers every
//   solver.self_collision_every substeps and on the last) -> velocities from positions ->
//   plastic update (seed 001 III.C; each substep one solver.plasticity_every-th of the links,
//   in turn, so each link every plasticity_every substeps).
// Link constants are rebuilt only when links_version() or dt_s change; target-spring
// weights once per frame (rows interleaved so consecutive ones seldom share a node).
// Contacts: candidates are detected with a margin that also covers a skin of motion (and,
// for layers, the skin beside each triangle) and kept over frames while 2 mm + the largest
// node move since the detection + 1.5 x this frame's largest possible move (plus what the
// external substep contacts say they may push a node this frame) stays within
// that margin (the per-frame rule, 2 mm + 1.5 x the frame's move, over the whole time they
// are used); detected again when it does not, when the collision world changed (version())
// or after set_positions. Every frame, the candidates that pass the per-frame rule are the
// active ones (ContactSolver::select_rt), each layer contact taking the node's current side.
// Prediction, velocities and target springs run 4 doubles at a time (AVX2+FMA, runtime
// check; force_scalar_passes for tests).
// Storage is allocated in the constructor; step_rt allocates nothing.
#pragma once

#include <cstdint>
#include <vector>

#include "contacts.h"
#include "keypoint_coupling.h"
#include "link_kernel.h"
#include "sheet_model.h"
#include "strain_limit.h"
#include "substep_contacts.h"

namespace crease::sheet {

class XpbdSheet final : public SheetModel {
 public:
  explicit XpbdSheet(const SheetParams& params);

  void step_rt(double dt_s) noexcept override;
  [[nodiscard]] std::span<const Vec3> positions() const noexcept override { return x_; }
  [[nodiscard]] std::span<const Vec3> velocities() const noexcept override { return v_; }
  void set_positions(std::span<const Vec3> pos) noexcept override;
  [[nodiscard]] const char* backend_name() const noexcept override { return "xpbd"; }

  [[nodiscard]] const ContactStats& contact_stats() const noexcept { return contacts_.stats(); }
  [[nodiscard]] const LinkKernel& link_kernel() const noexcept { return kernel_; }
  LinkKernel& link_kernel() noexcept { return kernel_; }
  // The target and per-node passes without AVX2 even when the CPU has it (tests compare).
  void force_scalar_passes(bool on) noexcept { simd_ = !on && cpu_simd_; }
  // Contacts solved by another library in every substep (substep_contacts.h); nullptr: none.
  // Not owned; must outlive the model or be reset first. RT.
  void set_substep_contacts(SubstepContacts* c) noexcept { substep_contacts_ = c; }

 private:
  void prepare_frame(double dt_s) noexcept;
  void project_links() noexcept;
  void prepare_targets(double dt_s) noexcept;
  void project_targets() noexcept;
  void prepare_normal_targets(double dt_s) noexcept;
  void project_normal_targets() noexcept;
  // The next EVERY-th of plastic_links_, in blocks of 8.
  void update_plasticity(int every) noexcept;
  void mark_unseen() noexcept;
  void limit_unseen(double dts) noexcept;
  void mark_hidden_held(double within_mm) noexcept;
  void hold_hidden() noexcept;
  void detect_contacts(double dt_s) noexcept;

  std::vector<Vec3> x_, v_, prev_;
  KeypointCoupling coupling_;  // seed 000 Eqs. 1-4, applied every substep
  std::vector<double> w_;  // inverse mass, 0 for pinned nodes, 1/kg
  struct TargetRow {        // one zero-length target spring, fixed within a frame
    std::int32_t node[4];
    double b[4], wb[4];     // bilinear weights; w_e * b_e
    double inv_den;         // 1 / (sum w_e b_e^2 + alpha_input / dt_s^2), 0: inactive
    Vec3 world;             // target, mm
  };
  std::vector<TargetRow> target_rows_;  // capacity kMaxTargets
  struct NormalRow {        // one depth target, fixed within a frame
    std::int32_t node[4];
    double b[4], wb[4];
    double inv_den;         // 1 / (sum w_e b_e^2 + alpha / (weight dt_s^2)), 0: inactive
    Vec3 world;             // target, mm
    Vec3 normal;            // unit model normal at the sheet point (frame start); 0: 3-D spring
  };
  std::vector<NormalRow> normal_rows_;  // capacity kMaxTargets
  std::vector<Vec3> node_normals_;      // per node, for the depth targets
  bool cpu_simd_ = false, simd_ = false;  // AVX2+FMA target and per-node passes (runtime check)
  std::vector<std::int64_t> keep_;       // per xyz component: -1 free node, 0 pinned (node_passes.h)
  LinkKernel kernel_;                        // link data, refreshed when links_version() or dt_s change
  std::uint64_t prepared_version_ = ~std::uint64_t{0};
  double prepared_dt_ = 0.0;
  std::vector<std::int32_t> plastic_links_;  // elasto-plastic links
  // Per node, this frame's scratch: in a target's or key-point's stencil (mark_unseen), then in a
  // depth target's (mark_hidden_held).
  std::vector<std::uint8_t> touched_;
  std::vector<std::int32_t> unseen_;         // the free nodes not touched (this frame)
  int n_unseen_ = 0;
  std::vector<std::int32_t> hidden_held_;  // depth_hold_hidden_mm: the nodes held (this frame)
  int n_hidden_held_ = 0;
  std::ptrdiff_t plastic_cursor_ = 0;  // update_plasticity's next turn, 0 .. every - 1
  SubstepContacts* substep_contacts_ = nullptr;
  ContactSolver contacts_;
  StrainLimit strain_limit_;
  std::vector<Vec3> x_detect_;       // positions at the last contact detection
  double detect_margin_mm_ = -1.0;   // margin of the last detection; < 0: detect next frame
  const CollisionWorld* detect_world_ = nullptr;
  std::uint64_t detect_world_version_ = 0;
  std::uint64_t detections_ = 0;

 public:
  // Grid cells around a node a seen input touches within which nodes count as seen (the
  // unseen speed limit, SheetModel::set_unseen_speed_limit).
  static constexpr int kSeenReach = 0;
  // Extra motion the contact candidates cover, mm (0: found again every frame).
  static constexpr double kContactSkinMm = 8.0;
  // Contact detections since construction (tests, benchmark).
  [[nodiscard]] std::uint64_t contact_detections() const noexcept { return detections_; }
};

}  // namespace crease::sheet
