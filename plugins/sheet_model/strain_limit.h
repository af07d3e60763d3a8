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
// Long-range tethers (Kim, Chentanez, Mueller 2012, "Long range attachments"): every node not
// held stays within its distance on the sheet (x (1 + max_strain)) of a few anchors, held
// nodes at least kAnchorSpacingMm apart on the sheet (at most kMaxAnchors); it alone moves. A
// flap hung from a pinch, or a sheet dragged by a finger, is pulled in at once: through the
// links only, 4 sweeps a substep leave the far nodes of a 40-node chain stretched by 10-60 %.
// The bound is exact for the flat rectangle (its straight line on the sheet is its geodesic),
// so it never holds an inextensible sheet back. Its straight line may pass through what the
// paper wraps round (a table's edge), so a projection moves a node by kAnchorStepMm at most
// (without that cap, in a trial, the tether pulled the sheet into the table, whose slab then
// pushed it out below).
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
  [[nodiscard]] int anchor_count() const noexcept { return n_anchors_; }

  static constexpr double kHeldRatio = 100.0;  // held: hold >= this x the node's mass
  // Tethered held nodes per substep (the rest: links only); their pairs cost kMaxHeld^2 / 2 a
  // sweep (a fingertip holds 2-10 of the world's nodes).
  static constexpr int kMaxHeld = 64;
  // Long-range anchors: held nodes this far apart on the sheet at least (mm; a fingertip's
  // patch, 2-10 nodes 7.4 mm apart, gives one or two), at most kMaxAnchors (their cost:
  // kMaxAnchors x nodes a substep).
  static constexpr double kAnchorSpacingMm = 15.0;
  static constexpr int kMaxAnchors = 8;
  // How far one anchor's tether moves a node in one projection (mm; 4 m/s at 0.5 ms substeps).
  static constexpr double kAnchorStepMm = 2.0;

 private:
  void pick_anchors() noexcept;
  void tether_to_anchors(std::span<Vec3> x, std::size_t n, double grow) noexcept;

  std::vector<std::int32_t> a_, b_;
  std::vector<double> max_len_, rest_;
  std::vector<double> wl_;          // per node: the weight this projection uses
  std::vector<Vec2> uv_;            // per node: where it lies on the sheet (mm)
  std::vector<std::int32_t> held_;  // this substep's held nodes (capacity kMaxHeld)
  std::vector<std::int32_t> anchors_;  // among them, the long-range anchors (capacity kMaxAnchors)
  std::vector<std::uint8_t> is_held_;  // per node, this substep
  int n_held_ = 0, n_anchors_ = 0;
  double prepared_strain_ = -1;
};

}  // namespace crease::sheet
