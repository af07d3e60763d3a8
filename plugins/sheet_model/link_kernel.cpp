#include "link_kernel.h"

#include <cmath>

namespace crease::sheet {

void project_links_rt(const PackedLinks& l, double* x) noexcept {
  const int m = l.size();
  for (int k = 0; k < m; ++k) {
    double* pa = x + 3 * l.a[k];
    double* pb = x + 3 * l.b[k];
    const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], dz = pb[2] - pa[2];
    const double len2 = dx * dx + dy * dy + dz * dz;
    if (!(len2 > 1e-18)) continue;
    // x_a += w_a (|d| - l) / (w_a + w_b + alpha/dt_s^2) d/|d|; x_b likewise with -.
    const double s = 1.0 - l.rest[k] / std::sqrt(len2);
    const double fa = l.wa[k] * s, fb = l.wb[k] * s;
    pa[0] += fa * dx;
    pa[1] += fa * dy;
    pa[2] += fa * dz;
    pb[0] -= fb * dx;
    pb[1] -= fb * dy;
    pb[2] -= fb * dz;
  }
}

}  // namespace crease::sheet
