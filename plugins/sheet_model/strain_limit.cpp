#include "strain_limit.h"

#include <algorithm>
#include <cmath>

namespace crease::sheet {
namespace {

// Nodes A and B no further apart than LIM (mm), each moved by its weight's share. False when
// they were not (or nothing can move).
bool limit_pair(std::span<Vec3> x, std::int32_t a, std::int32_t b, double lim, double wa,
                double wb) noexcept {
  const Vec3 d = x[b] - x[a];
  const double len2 = dot(d, d);
  if (len2 <= lim * lim || !(wa + wb > 0)) return false;
  const double len = std::sqrt(len2);
  const Vec3 corr = ((len - lim) / (len * (wa + wb))) * d;
  x[a] += wa * corr;
  x[b] -= wb * corr;
  return true;
}

}  // namespace

void StrainLimit::configure(const Topology& topo, std::span<const double> rest) {
  a_.clear();
  b_.clear();
  rest_.clear();
  for (int k = 0; k < topo.link_count(); ++k) {
    if (topo.kind[k] != LinkKind::structural) continue;
    a_.push_back(topo.a[k]);
    b_.push_back(topo.b[k]);
    rest_.push_back(rest[static_cast<std::size_t>(k)]);
  }
  max_len_.assign(rest_.size(), 0.0);
  wl_.assign(static_cast<std::size_t>(topo.grid.count()), 0.0);
  uv_.resize(static_cast<std::size_t>(topo.grid.count()));
  for (int i = 0; i < topo.grid.count(); ++i)
    uv_[static_cast<std::size_t>(i)] = topo.grid.sheet_of(i);
  held_.assign(kMaxHeld, 0);
  n_held_ = 0;
  prepared_strain_ = -1;
}

void StrainLimit::project_rt(std::span<Vec3> x, std::span<const double> w,
                             std::span<const double> hold, double max_strain, int sweeps) noexcept {
  if (!(max_strain > 0) || a_.empty()) return;
  if (max_strain != prepared_strain_) {
    for (std::size_t k = 0; k < rest_.size(); ++k) max_len_[k] = (1.0 + max_strain) * rest_[k];
    prepared_strain_ = max_strain;
  }
  const std::size_t n = std::min(w.size(), wl_.size());
  n_held_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double h = i < hold.size() ? std::max(0.0, hold[i]) : 0.0;
    const double r = w[i] * h;  // the hold over the node's mass
    wl_[i] = w[i] > 0 ? w[i] / (1.0 + r) : 0.0;
    // Held: its hold outweighs its own mass kHeldRatio times over.
    if (w[i] > 0 && r >= kHeldRatio && n_held_ < static_cast<int>(held_.size()))
      held_[static_cast<std::size_t>(n_held_++)] = static_cast<std::int32_t>(i);
  }
  // Tethers between held nodes: no further apart than their distance on the sheet allows.
  const double grow = 1.0 + max_strain;
  for (int s = 0; s < sweeps; ++s) {
    for (int p = 0; p < n_held_; ++p) {
      const std::int32_t a = held_[static_cast<std::size_t>(p)];
      for (int q = p + 1; q < n_held_; ++q) {
        const std::int32_t b = held_[static_cast<std::size_t>(q)];
        const double du = uv_[b].u - uv_[a].u, dv = uv_[b].v - uv_[a].v;
        (void)limit_pair(x, a, b, grow * std::sqrt(du * du + dv * dv), wl_[a], wl_[b]);
      }
    }
  }
  const int m = link_count();
  for (int s = 0; s < sweeps; ++s) {
    bool any = false;
    for (int q = 0; q < m; ++q) {
      const int k = (s % 2 == 0) ? q : m - 1 - q;
      if (limit_pair(x, a_[k], b_[k], max_len_[k], wl_[a_[k]], wl_[b_[k]])) any = true;
    }
    if (!any) break;
  }
}

}  // namespace crease::sheet
