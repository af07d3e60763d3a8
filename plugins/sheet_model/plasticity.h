// Elasto-plastic link (seed 001 III.C): bilinear plasticity with kinematic hardening.
// Rules, applied after every substep to a link's elongation dl = |x2 - x1| - l:
//   1) the permanent elongation dl_p starts at 0;
//   2) the elastic region of dl is [dl_p/a - dl_Y, dl_p/a + dl_Y];
//   3) when dl leaves that region by dl_over, a*dl_over is added to dl_p.
// dl_Y = eps_Y * l (the paper prints eps_Y / l, which is not a length: a typo).
// The spring's rest length is l + dl_p (seed 001 Eqs. 2-3).
#pragma once

namespace crease::sheet {

// Returns the new permanent elongation. `a` in [0, 1); a == 0 leaves dl_p unchanged.
[[nodiscard]] inline double plastic_update(double dl, double dl_p, double a, double dl_yield) noexcept {
  if (a <= 0.0) return dl_p;
  const double center = dl_p / a;
  const double upper = center + dl_yield;
  const double lower = center - dl_yield;
  if (dl > upper) return dl_p + a * (dl - upper);
  if (dl < lower) return dl_p + a * (dl - lower);
  return dl_p;
}

}  // namespace crease::sheet
