#include "xpbd_sheet.h"

#include <algorithm>
#include <cmath>

#include "plasticity.h"

namespace crease::sheet {

XpbdSheet::XpbdSheet(const SheetParams& params) : SheetModel(params) {
  const int n = node_count();
  x_ = flat_;
  v_.assign(n, Vec3{});
  prev_ = flat_;
  kvel_.assign(n, Vec3{});
  kweight_.assign(n, 0.0);
  w_.assign(n, 0.0);
  const int m = link_count();
  // Greedy colouring in link order (structural links first), then a stable sort by colour.
  std::vector<std::uint64_t> used(static_cast<std::size_t>(n) * 4, 0);  // 256 colours max
  std::vector<int> colour(m, 0);
  for (int k = 0; k < m; ++k) {
    const std::uint64_t* ua = &used[4 * static_cast<std::size_t>(topo_.a[k])];
    const std::uint64_t* ub = &used[4 * static_cast<std::size_t>(topo_.b[k])];
    int c = 0;
    while (c < 255 && (((ua[c / 64] | ub[c / 64]) >> (c % 64)) & 1u) != 0) ++c;
    colour[k] = c;
    used[4 * static_cast<std::size_t>(topo_.a[k]) + c / 64] |= std::uint64_t{1} << (c % 64);
    used[4 * static_cast<std::size_t>(topo_.b[k]) + c / 64] |= std::uint64_t{1} << (c % 64);
    colours_ = std::max(colours_, c + 1);
  }
  std::vector<int> by_colour(m);
  for (int k = 0; k < m; ++k) by_colour[k] = k;
  std::stable_sort(by_colour.begin(), by_colour.end(), [&colour](int p, int q) { return colour[p] < colour[q]; });
  order_ = by_colour;
  const int slots = m;
  links_.a.assign(slots, 0);
  links_.b.assign(slots, 0);
  links_.rest.assign(slots, 0.0);
  links_.wa.assign(slots, 0.0);
  links_.wb.assign(slots, 0.0);
  const SolverParams& s = params_.solver;
  if (s.plasticity_rate > 0) {
    for (int p = 0; p < slots; ++p)
      if (!s.plastic_bending_only || topo_.kind[order_[p]] == LinkKind::bending)
        plastic_links_.push_back(p);
  }
  contacts_.configure(topo_, params_.grid, s);
}

void XpbdSheet::set_positions(std::span<const Vec3> pos) noexcept {
  const std::size_t n = std::min(pos.size(), x_.size());
  for (std::size_t i = 0; i < n; ++i) {
    x_[i] = pos[i];
    prev_[i] = pos[i];
    v_[i] = Vec3{};
  }
}

void XpbdSheet::prepare_frame(double dt_s) noexcept {
  const double inv_dts2 = 1.0 / (dt_s * dt_s);
  for (int i = 0; i < node_count(); ++i) w_[i] = pinned_[i] ? 0.0 : 1.0 / mass_[i];
  const int slots = static_cast<int>(order_.size());
  for (int p = 0; p < slots; ++p) {
    const int k = order_[p];
    const double wa = w_[topo_.a[k]], wb = w_[topo_.b[k]];
    const double den = wa + wb + compliance_[k] * inv_dts2;
    const double inv = den > 0 ? 1.0 / den : 0.0;
    links_.a[p] = topo_.a[k];
    links_.b[p] = topo_.b[k];
    links_.rest[p] = rest_[k] + plastic_[k];
    links_.wa[p] = wa * inv;
    links_.wb[p] = wb * inv;
  }
}

// seed 000 Eqs. 1-3: v_l = lambda (k^w - c^w(k^m)); node velocity targets alpha_q v_l,
// accumulated over key-points. A node with total influence W >= 1 takes the accumulated
// velocity (Eq. 4 when k^m is a node); below 1 it keeps (1 - W) of its own velocity.
void XpbdSheet::apply_keypoint_velocities(double dt_s) noexcept {
  if (n_keypoints_ == 0) return;
  // A gain above 1/dt_s would overshoot the key-point within one substep.
  const double lambda = std::min(keypoint_gain_, 1.0 / dt_s);
  if (!(lambda > 0)) return;
  for (int l = 0; l < n_keypoints_; ++l) {
    const SheetPointStencil& s = keypoint_stencil_[l];
    Vec3 c;
    for (int e = 0; e < 4; ++e) c += s.bilinear[e] * x_[s.node[e]];
    const Vec3 vl = lambda * (keypoints_[l].world_mm - c);
    for (int e = 0; e < 4; ++e) {
      if (s.alpha[e] <= 0) continue;
      kvel_[s.node[e]] += s.alpha[e] * vl;
      kweight_[s.node[e]] += s.alpha[e];
    }
  }
  for (int i = 0; i < node_count(); ++i) {
    if (kweight_[i] > 0) {
      v_[i] = (1.0 - std::min(kweight_[i], 1.0)) * v_[i] + kvel_[i];
      kvel_[i] = Vec3{};
      kweight_[i] = 0.0;
    }
  }
}

void XpbdSheet::project_links() noexcept {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 must be three packed doubles");
  project_links_rt(links_, &x_[0].x);
}

// seed 001 Eq. 4, generalised to a bilinear sheet point c = sum b_e x_e:
// x_e -= w_e b_e (c - x_d) / (sum w_e b_e^2 + alpha_input / dt_s^2).
void XpbdSheet::project_targets(double dt_s) noexcept {
  const double at = params_.solver.target_compliance_m_per_n / (dt_s * dt_s);
  for (int t = 0; t < n_targets_; ++t) {
    const SheetPointStencil& s = target_stencil_[t];
    Vec3 c;
    double den = at;
    for (int e = 0; e < 4; ++e) {
      c += s.bilinear[e] * x_[s.node[e]];
      den += w_[s.node[e]] * s.bilinear[e] * s.bilinear[e];
    }
    if (!(den > 0)) continue;
    const Vec3 err = (1.0 / den) * (c - targets_[t].world_mm);
    for (int e = 0; e < 4; ++e) x_[s.node[e]] -= (w_[s.node[e]] * s.bilinear[e]) * err;
  }
}

void XpbdSheet::update_plasticity() noexcept {
  const double a = params_.solver.plasticity_rate;
  const double eps_y = params_.solver.yield_strain;
  for (const std::int32_t p : plastic_links_) {
    const int k = order_[p];
    const double l = rest_[k];
    const double dl = norm(x_[topo_.b[k]] - x_[topo_.a[k]]) - l;
    plastic_[k] = plastic_update(dl, plastic_[k], a, eps_y * l);
    links_.rest[p] = l + plastic_[k];
  }
}

void XpbdSheet::step_rt(double dt) noexcept {
  if (!(dt > 0) || !std::isfinite(dt)) return;
  const SolverParams& sp = params_.solver;
  const int ns = sp.substeps;
  const double dts = dt / ns;
  prepare_frame(dts);
  const int n = node_count();
  // Collision candidates once per frame, with a margin covering this frame's motion.
  double vmax = 0;
  for (int i = 0; i < n; ++i) vmax = std::max(vmax, norm(v_[i]));
  const double margin = std::min(2.0 + 1.5 * vmax * dt, 30.0);
  contacts_.detect_rt(x_, world_, margin);

  const double damp = std::max(0.0, 1.0 - sp.damping_per_s * dts);
  const double vcap = sp.max_speed_mm_per_s;
  for (int s = 0; s < ns; ++s) {
    apply_keypoint_velocities(dts);
    for (int i = 0; i < n; ++i) {  // seed 001 Eq. 1
      prev_[i] = x_[i];
      if (pinned_[i]) {
        x_[i] = pin_pos_[i];
        continue;
      }
      v_[i] = damp * (v_[i] + dts * sp.gravity_mm_per_s2);
      x_[i] += dts * v_[i];
    }
    project_links();
    project_targets(dts);
    contacts_.solve_rt(x_, prev_, w_);
    const double inv = 1.0 / dts;
    for (int i = 0; i < n; ++i) {
      if (pinned_[i]) {
        v_[i] = Vec3{};
        continue;
      }
      Vec3 v = inv * (x_[i] - prev_[i]);
      const double sp2 = dot(v, v);
      if (sp2 > vcap * vcap) {  // speed limit: the move of this substep is shortened too
        v *= vcap / std::sqrt(sp2);
        x_[i] = prev_[i] + dts * v;
      }
      v_[i] = v;
    }
    if (!plastic_links_.empty()) update_plasticity();
  }
}

}  // namespace crease::sheet
