// The ODE backend (seed 000 modelled the sheet in a physics engine): one ODE body per node,
// one soft distance joint (dJointTypeDBall, spring via ERP/CFM) per link, the same
// topology, masses, creases, memory, plasticity and coupling as the XPBD backend.
// Contacts (shapes found by ODE's dCollide, and layers) are enforced after each ODE step by
// the XPBD backend's contact projection with friction, velocities corrected by the move
// (ODE contact joints were tried: with mu = 0.5 the draped sheet crept off a fingertip).
// ODE's implicit joints need fewer steps than XPBD substeps: `steps_per_frame` dWorldQuickStep
// calls per step_rt (the coupling is applied at each). ODE allocates from its own arenas
// (malloc, not operator new), reused after the first steps.
#pragma once

#include <vector>

#include "contacts.h"
#include "keypoint_coupling.h"
#include "sheet_model.h"

struct dxWorld;
struct dxBody;
struct dxJoint;

namespace crease::sheet {

class OdeSheet final : public SheetModel {
 public:
  explicit OdeSheet(const SheetParams& params, int quickstep_iterations = 10, int steps_per_frame = 5);
  ~OdeSheet() override;

  void step_rt(double dt_s) noexcept override;
  [[nodiscard]] std::span<const Vec3> positions() const noexcept override { return x_; }
  [[nodiscard]] std::span<const Vec3> velocities() const noexcept override { return v_; }
  void set_positions(std::span<const Vec3> pos) noexcept override;
  [[nodiscard]] const char* backend_name() const noexcept override { return "ode"; }

 private:
  void sync_links(double dt_s) noexcept;  // rest lengths and ERP/CFM from the shared state
  void read_bodies() noexcept;
  void substep(double dts) noexcept;

  dxWorld* ode_world_ = nullptr;
  std::vector<dxBody*> bodies_;
  std::vector<dxJoint*> joints_;
  std::vector<Vec3> x_, v_, prev_, force_;
  std::vector<double> w_;
  KeypointCoupling coupling_;  // seed 000 Eqs. 1-4, applied before every ODE step
  std::uint64_t synced_version_ = ~std::uint64_t{0};
  double synced_dt_ = 0;
  int steps_per_frame_ = 5;
  std::vector<std::uint8_t> kinematic_;
  ContactSolver layers_;
};

}  // namespace crease::sheet
