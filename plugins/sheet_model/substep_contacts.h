// Contacts that another library solves inside the sheet's substeps: the simulated world's
// fingers (plugins/sim_world) press, pinch and drag the sheet with their own contact model
// (compliant pads, per-surface friction, the reaction on the finger), which must act in every
// substep beside the links, not once per frame.
//
// XpbdSheet calls solve_rt in every substep after the links and the target springs and before
// its own contacts (table and shapes, then layers), so the layers always have the last word:
// a node pushed through another layer by a finger is put back on its side in the same substep.
// RT: implementations allocate nothing, take no lock, never throw.
#pragma once

#include <span>

#include "vec3.h"

namespace crease::sheet {

class SubstepContacts {
 public:
  virtual ~SubstepContacts() = default;

  // x: positions (moved by the implementation), prev: positions at the substep's start,
  // w: inverse masses (1/kg, 0 = pinned: leave alone). substep in [0, substeps), dt_s the
  // substep's length (s).
  virtual void solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w, int substep,
                        int substeps, double dt_s) noexcept = 0;

  // The largest distance (mm) these contacts may move a node within the coming frame of dt_s:
  // the sheet's contact candidates (table, layers) must cover it. Called once per frame
  // before the substeps. RT.
  [[nodiscard]] virtual double max_push_mm(double dt_s) const noexcept = 0;

  // Per node, after solve_rt: how firmly these contacts hold it in this substep, as a mass (kg;
  // strain_limit.h: the friction it can take, mu F, over 1 g). Empty: they hold nothing. RT.
  [[nodiscard]] virtual std::span<const double> hold_mass_kg() const noexcept { return {}; }
};

}  // namespace crease::sheet
