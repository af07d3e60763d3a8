// The substep XPBD backend (seed 001 III.A-C, seed 000 IV.B coupling).
// One frame of dt: N_s substeps of dt_s = dt / N_s, each:
//   key-point velocities (seed 000 Eqs. 1-4) -> prediction (seed 001 Eq. 1) ->
//   links, Gauss-Seidel, one pass, lambda = 0 per substep (seed 001 Eqs. 2-3) ->
//   zero-length target springs (seed 001 Eq. 4) -> contacts (table, shapes, layers) ->
//   velocities from positions -> plastic update (seed 001 III.C).
// Storage is allocated in the constructor; step_rt allocates nothing.
#pragma once

#include <cstdint>
#include <vector>

#include "contacts.h"
#include "link_kernel.h"
#include "sheet_model.h"

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
  [[nodiscard]] int link_colours() const noexcept { return colours_; }

 private:
  void prepare_frame(double dt_s) noexcept;
  void apply_keypoint_velocities(double dt_s) noexcept;
  void project_links() noexcept;
  void project_targets(double dt_s) noexcept;
  void update_plasticity() noexcept;

  std::vector<Vec3> x_, v_, prev_, kvel_;
  std::vector<double> kweight_;
  std::vector<double> w_;  // inverse mass, 0 for pinned nodes, 1/kg
  PackedLinks links_;                        // refreshed at the start of every frame
  std::vector<std::int32_t> order_;          // storage slot -> link index
  std::vector<std::int32_t> plastic_links_;  // storage slots of elasto-plastic links
  int colours_ = 0;
  ContactSolver contacts_;
};

}  // namespace crease::sheet
