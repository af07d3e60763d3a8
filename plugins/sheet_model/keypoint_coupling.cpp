#include "keypoint_coupling.h"

#include <algorithm>
#include <cmath>

namespace crease::sheet {

void KeypointCoupling::configure(int nodes) {
  const auto n = static_cast<std::size_t>(std::max(nodes, 0));
  vel_.assign(n, Vec3{});
  weight_.assign(n, 0.0);
  touched_.assign(n, 0);
  n_touched_ = 0;
}

std::span<const std::int32_t> KeypointCoupling::apply_rt(
    std::span<const KeypointObs> keypoints, std::span<const SheetPointStencil> stencils,
    double gain_per_s, double dt_s, std::span<const Vec3> x, std::span<Vec3> v,
    std::span<const std::uint8_t> pinned) noexcept {
  n_touched_ = 0;
  const std::size_t n_kp = std::min(keypoints.size(), stencils.size());
  if (n_kp == 0 || !(dt_s > 0)) return {};
  const double lambda = std::min(gain_per_s, 1.0 / dt_s);
  if (!(lambda > 0)) return {};
  const auto nodes =
      static_cast<std::int32_t>(std::min({x.size(), v.size(), pinned.size(), weight_.size()}));
  for (std::size_t l = 0; l < n_kp; ++l) {
    const SheetPointStencil& s = stencils[l];
    bool inside = true;
    for (int e = 0; e < 4; ++e) inside = inside && s.node[e] >= 0 && s.node[e] < nodes;
    if (!inside) continue;
    Vec3 c;
    for (int e = 0; e < 4; ++e) c += s.bilinear[e] * x[s.node[e]];
    const Vec3 vl = lambda * (keypoints[l].world_mm - c);  // Eq. 1
    for (int e = 0; e < 4; ++e) {
      const std::int32_t q = s.node[e];
      if (!(s.alpha[e] > 0) || pinned[q] != 0) continue;
      if (weight_[q] == 0.0) touched_[n_touched_++] = q;
      vel_[q] += s.alpha[e] * vl;  // Eq. 3, accumulated
      weight_[q] += s.alpha[e];
    }
  }
  for (int t = 0; t < n_touched_; ++t) {
    const std::int32_t q = touched_[t];
    v[q] = (1.0 - std::min(weight_[q], 1.0)) * v[q] + vel_[q];
    vel_[q] = Vec3{};
    weight_[q] = 0.0;
  }
  return {touched_.data(), static_cast<std::size_t>(n_touched_)};
}

}  // namespace crease::sheet
