// The XPBD inner loop over links (seed 001 Eqs. 2-3, lambda = 0 per substep), on links
// packed structure-of-arrays in colour order: within a colour no two links share a node, so
// consecutive projections are independent and the CPU overlaps them (measured 2026-11-21 on
// the CI kind of machine: 4-5x faster than link order; an AVX2 gather/scatter version of
// this loop was no faster in the solver and was dropped).
#pragma once

#include <cstdint>
#include <vector>

namespace crease::sheet {

struct PackedLinks {
  std::vector<std::int32_t> a, b;  // node indices
  std::vector<double> rest;        // l + dl_p, mm
  std::vector<double> wa, wb;      // w_a / (w_a + w_b + alpha / dt_s^2), likewise b
  [[nodiscard]] int size() const noexcept { return static_cast<int>(a.size()); }
};

// One Gauss-Seidel pass. x: node positions as x0 y0 z0 x1 y1 z1 ... RT.
void project_links_rt(const PackedLinks& links, double* x) noexcept;

}  // namespace crease::sheet
