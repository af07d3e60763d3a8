// Strain limiting of the sheet's structural links (paper does not stretch): after the
// substep's links and the contacts other code solves (the world's fingers, whose holds weight
// it), every structural link longer than (1 + max_strain) x its rest length is shortened to
// that, in a few Gauss-Seidel sweeps (alternating direction).
// Why: one XPBD pass per substep gives a link an effective stiffness of only ~m / dt_s^2
// (a 4 mg node at 0.5 ms substeps: ~17 mN per mm), so a sheet dragged over the table, hung
// from a pinch or pulled against a pressing finger stretched by tens of percent; the limit
// makes it inextensible to a tolerance.
// Who gives way: hold (kg) is what the contacts say holds a node this substep
// (SubstepContacts::hold_mass_kg: the friction it can take, mu F, as the mass that force would
// accelerate at 1 g); a node moves in proportion to 1 / (m + hold). A link between a node pressed
// by a finger and a free one moves the free one; between two holds the weaker gives most.
// Held nodes (hold >= kHeldRatio x m) are also tethered pairwise: no further apart than their
// distance on the sheet (x (1 + max_strain)) allows. Through the free nodes between them the links
// would take hundreds of sweeps to pull two holds together (each sweep moves a held node by
// m / hold of what is left); the tether does it in one.
// (Weights as 1 / hold^2, nearer Coulomb's "the weaker slips, the stronger holds", lost the pinch
// in the trials more often: tried, not kept.)
// Units: mm, kg. RT after configure(): no allocation.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "topology.h"
#include "vec3.h"

namespace crease::sheet {

class StrainLimit {
 public:
  // The structural links of TOPO with rest lengths REST (mm, one per link of TOPO). Allocates.
  void configure(const Topology& topo, std::span<const double> rest);

  // x: positions (moved); w: inverse masses (1/kg, 0: pinned, never moved); hold: extra mass per
  // node (kg; empty: none). max_strain: 0.01 allows 1 % stretch; <= 0: does nothing. sweeps: of
  // the tethers, then of the links (the links stop early once none is over). RT.
  void project_rt(std::span<Vec3> x, std::span<const double> w, std::span<const double> hold,
                  double max_strain, int sweeps) noexcept;

  [[nodiscard]] int link_count() const noexcept { return static_cast<int>(a_.size()); }
  [[nodiscard]] int held_count() const noexcept { return n_held_; }

  static constexpr double kHeldRatio = 100.0;  // held: hold >= this x the node's mass
  // Tethered held nodes per substep (the rest: links only); their pairs cost kMaxHeld^2 / 2 a
  // sweep (a fingertip holds 2-10 of the world's nodes).
  static constexpr int kMaxHeld = 64;

 private:
  std::vector<std::int32_t> a_, b_;
  std::vector<double> max_len_, rest_;
  std::vector<double> wl_;          // per node: the weight this projection uses
  std::vector<Vec2> uv_;            // per node: where it lies on the sheet (mm)
  std::vector<std::int32_t> held_;  // this substep's held nodes (capacity kMaxHeld)
  int n_held_ = 0;
  double prepared_strain_ = -1;
};

}  // namespace crease::sheet
