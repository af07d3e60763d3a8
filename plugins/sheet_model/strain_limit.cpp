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
  anchors_.assign(kMaxAnchors, 0);
  is_held_.assign(static_cast<std::size_t>(topo.grid.count()), 0);
  n_held_ = 0;
  n_anchors_ = 0;
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
    const bool held = w[i] > 0 && r >= kHeldRatio && n_held_ < static_cast<int>(held_.size());
    is_held_[i] = held ? 1 : 0;
    if (held) held_[static_cast<std::size_t>(n_held_++)] = static_cast<std::int32_t>(i);
  }
  pick_anchors();
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
  if (n_anchors_ > 0) tether_to_anchors(x, n, grow);
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

void StrainLimit::pick_anchors() noexcept {
  n_anchors_ = 0;
  const double spacing2 = kAnchorSpacingMm * kAnchorSpacingMm;
  for (int p = 0; p < n_held_ && n_anchors_ < kMaxAnchors; ++p) {
    const Vec2 h = uv_[static_cast<std::size_t>(held_[static_cast<std::size_t>(p)])];
    bool apart = true;
    for (int q = 0; q < n_anchors_ && apart; ++q) {
      const Vec2 a = uv_[static_cast<std::size_t>(anchors_[static_cast<std::size_t>(q)])];
      apart = (h.u - a.u) * (h.u - a.u) + (h.v - a.v) * (h.v - a.v) >= spacing2;
    }
    if (apart)
      anchors_[static_cast<std::size_t>(n_anchors_++)] = held_[static_cast<std::size_t>(p)];
  }
}

void StrainLimit::tether_to_anchors(std::span<Vec3> x, std::size_t n, double grow) noexcept {
  const double grow2 = grow * grow;
  for (int q = 0; q < n_anchors_; ++q) {
    const auto a = static_cast<std::size_t>(anchors_[static_cast<std::size_t>(q)]);
    const Vec3 xa = x[a];
    const Vec2 ua = uv_[a];
    for (std::size_t i = 0; i < n; ++i) {
      if (is_held_[i] != 0 || !(wl_[i] > 0)) continue;  // held nodes: the pairwise tethers
      const Vec3 d = x[i] - xa;
      const double len2 = dot(d, d);
      const double du = uv_[i].u - ua.u, dv = uv_[i].v - ua.v;
      const double lim2 = grow2 * (du * du + dv * dv);
      if (len2 <= lim2) continue;
      const double len = std::sqrt(len2);
      // Towards the sphere about the anchor, at most kAnchorStepMm: the straight line may cross
      // what the paper wraps round (the table's edge), whose contacts push back only so far.
      x[i] -= (std::min(len - std::sqrt(lim2), kAnchorStepMm) / len) * d;
    }
  }
}

}  // namespace crease::sheet
