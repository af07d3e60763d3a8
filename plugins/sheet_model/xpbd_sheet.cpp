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
  target_rows_.resize(kMaxTargets);
  kernel_.configure(topo_);
  const SolverParams& s = params_.solver;
  if (s.plasticity_rate > 0) {
    for (int k = 0; k < link_count(); ++k)
      if (!s.plastic_bending_only || topo_.kind[k] == LinkKind::bending) plastic_links_.push_back(k);
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
  if (prepared_version_ == links_version_ && prepared_dt_ == dt_s) return;
  prepared_version_ = links_version_;
  prepared_dt_ = dt_s;
  const double inv_dts2 = 1.0 / (dt_s * dt_s);
  for (int i = 0; i < node_count(); ++i) w_[i] = pinned_[i] ? 0.0 : 1.0 / mass_[i];
  for (int k = 0; k < link_count(); ++k) {
    const double wa = w_[topo_.a[k]], wb = w_[topo_.b[k]];
    const double den = wa + wb + compliance_[k] * inv_dts2;
    const double inv = den > 0 ? 1.0 / den : 0.0;
    kernel_.set_link(k, rest_[k] + plastic_[k], wa * inv, wb * inv);
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
  kernel_.project_rt(x_);
}

// seed 001 Eq. 4, generalised to a bilinear sheet point c = sum b_e x_e:
// x_e -= w_e b_e (c - x_d) / (sum w_e b_e^2 + alpha_input / dt_s^2).
// The weights are fixed within a frame: computed once, applied every substep.
void XpbdSheet::prepare_targets(double dt_s) noexcept {
  const double at = params_.solver.target_compliance_m_per_n / (dt_s * dt_s);
  for (int t = 0; t < n_targets_; ++t) {
    const SheetPointStencil& s = target_stencil_[t];
    TargetRow& r = target_rows_[t];
    double den = at;
    for (int e = 0; e < 4; ++e) {
      r.node[e] = s.node[e];
      r.b[e] = s.bilinear[e];
      r.wb[e] = w_[s.node[e]] * s.bilinear[e];
      den += r.wb[e] * s.bilinear[e];
    }
    r.inv_den = den > 0 ? 1.0 / den : 0.0;
    r.world = targets_[t].world_mm;
  }
}

void XpbdSheet::project_targets() noexcept {
  Vec3* x = x_.data();
  for (int t = 0; t < n_targets_; ++t) {
    const TargetRow r = target_rows_[t];  // a copy: the stores to x cannot alias it
    if (!(r.inv_den > 0)) continue;
    const Vec3 c = r.b[0] * x[r.node[0]] + r.b[1] * x[r.node[1]] + r.b[2] * x[r.node[2]] + r.b[3] * x[r.node[3]];
    const Vec3 err = r.inv_den * (c - r.world);
    for (int e = 0; e < 4; ++e) x[r.node[e]] -= r.wb[e] * err;
  }
}

void XpbdSheet::update_plasticity() noexcept {
  const double a = params_.solver.plasticity_rate;
  const double eps_y = params_.solver.yield_strain;
  for (const std::int32_t k : plastic_links_) {
    const double l = rest_[k];
    const double dl = norm(x_[topo_.b[k]] - x_[topo_.a[k]]) - l;
    plastic_[k] = plastic_update(dl, plastic_[k], a, eps_y * l);
    kernel_.set_rest(k, l + plastic_[k]);
  }
}

void XpbdSheet::step_rt(double dt) noexcept {
  if (!(dt > 0) || !std::isfinite(dt)) return;
  const SolverParams& sp = params_.solver;
  const int ns = sp.substeps;
  const double dts = dt / ns;
  prepare_frame(dts);
  prepare_targets(dts);
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
    project_targets();
    const int every = std::max(1, sp.self_collision_every);
    contacts_.solve_rt(x_, prev_, w_, s % every == every - 1 || s == ns - 1);
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
