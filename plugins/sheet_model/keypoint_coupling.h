// Seed 000's key-point coupling (IV.B, Eqs. 1-4), one piece of code for every backend: a
// P-controller on node velocities that moves the model's sheet point c^w(k^m) of each
// observed key-point towards its world position k^w.
//   Eq. 1: v_l = lambda (k^w_l - c^w(k^m_l)), c^w bilinear over the 4 nodes around k^m_l
//   Eqs. 2-3: node q around k^m_l gets alpha_q v_l, alpha_q = max(1 - |k^m_l - n^m_q|, 0)
//             (grid units; SheetPointStencil::alpha), accumulated over all key-points
//   Eq. 4: a key-point on a node moves that node alone at lambda (k^w - n^w)
// Accumulated influence W_q = sum alpha_q: a node with W_q >= 1 takes the accumulated
// velocity; below 1 it keeps (1 - W_q) of its own velocity and adds the accumulated one.
// Pinned nodes are left alone. Velocities in mm/s, positions in mm, gain in 1/s.
// Storage is allocated by configure(); apply_rt allocates nothing.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "sheet_model.h"
#include "vec3.h"

namespace crease::sheet {

class KeypointCoupling {
 public:
  // Sizes the accumulators for `nodes` nodes (not RT).
  void configure(int nodes);

  // Sets v[q] for every free node q that one of the key-points influences (alpha_q > 0), from
  // the positions x (both spans of the node count). stencils[l] is the stencil of
  // keypoints[l].sheet_mm. The gain is clamped to 1 / dt_s (a larger one would overshoot the
  // key-point within one step); a gain <= 0 or no key-points changes nothing. Returns the
  // nodes whose velocity was set, each once, valid until the next call. RT.
  std::span<const std::int32_t> apply_rt(std::span<const KeypointObs> keypoints,
                                         std::span<const SheetPointStencil> stencils,
                                         double gain_per_s, double dt_s, std::span<const Vec3> x,
                                         std::span<Vec3> v,
                                         std::span<const std::uint8_t> pinned) noexcept;

 private:
  std::vector<Vec3> vel_;              // accumulated alpha_q v_l per node, mm/s; zero between calls
  std::vector<double> weight_;         // accumulated alpha_q per node; zero between calls
  std::vector<std::int32_t> touched_;  // nodes with weight_ > 0, in first-touch order
  int n_touched_ = 0;
};

}  // namespace crease::sheet
