#include "xpbd_sheet.h"

#include <algorithm>
#include <cmath>

#include "collision_world.h"
#include "node_passes.h"
#include "plasticity.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace crease::sheet {
namespace {

// One Gauss-Seidel pass over the target rows (see project_targets) with each node's xyz in
// one AVX2 register (masked to 3 lanes). The 4 nodes of a row are distinct (a grid cell).
#if defined(__x86_64__)
template <class Row>
__attribute__((target("avx2,fma"))) void project_targets_avx2(Vec3* x, const Row* rows, int n) noexcept {
  const __m256i m3 = _mm256_setr_epi64x(-1, -1, -1, 0);
  for (int t = 0; t < n; ++t) {
    const Row& r = rows[t];
    if (!(r.inv_den > 0)) continue;
    // Written out (no arrays): the loads and stores stay in registers.
    double* const p0 = &x[r.node[0]].x;
    double* const p1 = &x[r.node[1]].x;
    double* const p2 = &x[r.node[2]].x;
    double* const p3 = &x[r.node[3]].x;
    const __m256d q0 = _mm256_maskload_pd(p0, m3), q1 = _mm256_maskload_pd(p1, m3);
    const __m256d q2 = _mm256_maskload_pd(p2, m3), q3 = _mm256_maskload_pd(p3, m3);
    __m256d c = _mm256_mul_pd(_mm256_set1_pd(r.b[0]), q0);
    c = _mm256_fmadd_pd(_mm256_set1_pd(r.b[1]), q1, c);
    c = _mm256_fmadd_pd(_mm256_set1_pd(r.b[2]), q2, c);
    c = _mm256_fmadd_pd(_mm256_set1_pd(r.b[3]), q3, c);
    const __m256d w = _mm256_setr_pd(r.world.x, r.world.y, r.world.z, 0.0);
    const __m256d err = _mm256_mul_pd(_mm256_set1_pd(r.inv_den), _mm256_sub_pd(c, w));
    _mm256_maskstore_pd(p0, m3, _mm256_fnmadd_pd(_mm256_set1_pd(r.wb[0]), err, q0));
    _mm256_maskstore_pd(p1, m3, _mm256_fnmadd_pd(_mm256_set1_pd(r.wb[1]), err, q1));
    _mm256_maskstore_pd(p2, m3, _mm256_fnmadd_pd(_mm256_set1_pd(r.wb[2]), err, q2));
    _mm256_maskstore_pd(p3, m3, _mm256_fnmadd_pd(_mm256_set1_pd(r.wb[3]), err, q3));
  }
}
bool cpu_has_avx2_fma() noexcept {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
#else
template <class Row>
void project_targets_avx2(Vec3*, const Row*, int) noexcept {}
bool cpu_has_avx2_fma() noexcept { return false; }
#endif

}  // namespace

XpbdSheet::XpbdSheet(const SheetParams& params) : SheetModel(params) {
  const int n = node_count();
  x_ = flat_;
  v_.assign(n, Vec3{});
  prev_ = flat_;
  x_detect_ = flat_;
  coupling_.configure(n);
  w_.assign(n, 0.0);
  target_rows_.resize(kMaxTargets);
  normal_rows_.resize(kMaxTargets);
  node_normals_.resize(n);
  kernel_.configure(topo_);
  cpu_simd_ = cpu_has_avx2_fma() && node_passes_simd_available();
  simd_ = cpu_simd_;
  keep_.assign(3 * static_cast<std::size_t>(n), -1);
  touched_.assign(n, 0);
  unseen_.assign(n, 0);
  hidden_held_.assign(n, 0);
  const SolverParams& s = params_.solver;
  if (s.plasticity_rate > 0) {
    for (int k = 0; k < link_count(); ++k)
      if (!s.plastic_bending_only || topo_.kind[k] == LinkKind::bending) plastic_links_.push_back(k);
  }
  contacts_.configure(topo_, params_.grid, s);
  strain_limit_.configure(topo_, rest_);
}

void XpbdSheet::set_positions(std::span<const Vec3> pos) noexcept {
  const std::size_t n = std::min(pos.size(), x_.size());
  for (std::size_t i = 0; i < n; ++i) {
    x_[i] = pos[i];
    prev_[i] = pos[i];
    v_[i] = Vec3{};
  }
  detect_margin_mm_ = -1.0;
}

void XpbdSheet::prepare_frame(double dt_s) noexcept {
  if (prepared_version_ == links_version_ && prepared_dt_ == dt_s) return;
  prepared_version_ = links_version_;
  prepared_dt_ = dt_s;
  const double inv_dts2 = 1.0 / (dt_s * dt_s);
  for (int i = 0; i < node_count(); ++i) {
    w_[i] = pinned_[i] ? 0.0 : 1.0 / mass_[i];
    for (int c = 0; c < 3; ++c) keep_[3 * i + c] = pinned_[i] ? 0 : -1;
  }
  for (int k = 0; k < link_count(); ++k) {
    const double wa = w_[topo_.a[k]], wb = w_[topo_.b[k]];
    const double den = wa + wb + compliance_[k] * inv_dts2;
    const double inv = den > 0 ? 1.0 / den : 0.0;
    kernel_.set_link(k, rest_[k] + plastic_[k], wa * inv, wb * inv);
  }
}

void XpbdSheet::project_links() noexcept {
  kernel_.project_rt(x_);
}

// seed 001 Eq. 4, generalised to a bilinear sheet point c = sum b_e x_e:
// x_e -= w_e b_e (c - x_d) / (sum w_e b_e^2 + alpha_input / dt_s^2).
// The weights are fixed within a frame: computed once, applied every substep.
// Rows are stored in the order t = r, r + K, r + 2K, ... for r < K: key-points of one
// marker arrive together and share stencil nodes, so neighbours in that order seldom
// share a node and consecutive projections do not wait for each other's stores.
void XpbdSheet::prepare_targets(double dt_s) noexcept {
  constexpr int kInterleave = 7;
  const double at = params_.solver.target_compliance_m_per_n / (dt_s * dt_s);
  int row = 0;
  for (int first = 0; first < kInterleave; ++first) {
    for (int t = first; t < n_targets_; t += kInterleave) {
      const SheetPointStencil& s = target_stencil_[t];
      TargetRow& r = target_rows_[row++];
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
}

void XpbdSheet::project_targets() noexcept {
  Vec3* x = x_.data();
  if (simd_) {
    project_targets_avx2(x, target_rows_.data(), n_targets_);
    return;
  }
  for (int t = 0; t < n_targets_; ++t) {
    const TargetRow r = target_rows_[t];  // a copy: the stores to x cannot alias it
    if (!(r.inv_den > 0)) continue;
    const Vec3 c = r.b[0] * x[r.node[0]] + r.b[1] * x[r.node[1]] + r.b[2] * x[r.node[2]] + r.b[3] * x[r.node[3]];
    const Vec3 err = r.inv_den * (c - r.world);
    for (int e = 0; e < 4; ++e) x[r.node[e]] -= r.wb[e] * err;
  }
}

// Depth targets: seed 001 Eq. 4 on the sheet point c = sum b_e x_e, projected on the unit normal
// n there (taken at the frame's start: the model's, or with depth_surface_normal the bisector of
// the model's and the observed surface's when the target knows it): with d = c - x_d split into its
// normal part n (n . d) and the rest, x_e -= w_e b_e (n (n . d) + t (d - n (n . d))) / (sum w_e
// b_e^2 + alpha / (weight dt_s^2)), t = depth_tangential_weight. Without depth_along_normal, the
// 3-D spring of project_targets with that compliance.
void XpbdSheet::prepare_normal_targets(double dt_s) noexcept {
  if (n_normal_targets_ == 0) return;
  const bool along = params_.solver.depth_along_normal;
  const bool surface = params_.solver.depth_surface_normal;
  if (along) compute_normals(node_normals_);
  const double a = params_.solver.depth_compliance_m_per_n / (dt_s * dt_s);
  for (int t = 0; t < n_normal_targets_; ++t) {
    const SheetPointStencil& s = normal_stencil_[t];
    NormalRow& r = normal_rows_[t];
    double den = a / normal_targets_[t].weight;
    Vec3 n{};
    for (int e = 0; e < 4; ++e) {
      r.node[e] = s.node[e];
      r.b[e] = s.bilinear[e];
      r.wb[e] = w_[s.node[e]] * s.bilinear[e];
      den += r.wb[e] * s.bilinear[e];
      if (along) n += s.bilinear[e] * node_normals_[s.node[e]];
    }
    const Vec3 ns = normal_targets_[t].surface_normal;
    const double mn = norm(n);
    if (along && surface && norm(ns) > 0.5 && mn > 1e-9)
      n = (1.0 / mn) * n + (dot(ns, n) >= 0 ? 1.0 : -1.0) * ns;
    const double nn = norm(n);
    r.normal = along && nn > 1e-9 ? (1.0 / nn) * n : Vec3{};
    r.inv_den = den > 0 && (!along || nn > 1e-9) ? 1.0 / den : 0.0;
    r.world = normal_targets_[t].world_mm;
  }
}

void XpbdSheet::project_normal_targets() noexcept {
  Vec3* x = x_.data();
  const bool along = params_.solver.depth_along_normal;
  const double tw = params_.solver.depth_tangential_weight;
  for (int t = 0; t < n_normal_targets_; ++t) {
    const NormalRow& r = normal_rows_[t];
    if (!(r.inv_den > 0)) continue;
    const Vec3 c = r.b[0] * x[r.node[0]] + r.b[1] * x[r.node[1]] + r.b[2] * x[r.node[2]] + r.b[3] * x[r.node[3]];
    const Vec3 d = c - r.world;
    const Vec3 dn = dot(r.normal, d) * r.normal;
    const Vec3 err = along ? r.inv_den * (dn + tw * (d - dn)) : r.inv_den * d;
    for (int e = 0; e < 4; ++e) x[r.node[e]] -= r.wb[e] * err;
  }
}

void XpbdSheet::update_plasticity(int every) noexcept {
  const double a = params_.solver.plasticity_rate;
  const double eps_y = params_.solver.yield_strain;
  // One EVERY-th of the links after each substep, in blocks of kBlock consecutive links dealt
  // out in turn: each link every EVERY substeps, and no substep pays for all of them at once
  // (the world's step had a spike every 10 ms). Contiguous chunks instead moved
  // sim_world_fold's from-beyond fold by 10 mm (a chaotic scene); dealt out, by 0.1-0.3 mm. One
  // link in EVERY (no blocks) read every cache line of the links each substep: twice the time.
  const auto n = static_cast<std::ptrdiff_t>(plastic_links_.size());
  const std::ptrdiff_t phase = plastic_cursor_ % every;
  plastic_cursor_ = (phase + 1) % every;
  bool changed = false;
  constexpr std::ptrdiff_t kBlock = 8;
  for (std::ptrdiff_t e0 = phase * kBlock; e0 < n; e0 += every * kBlock)
    for (std::ptrdiff_t e = e0; e < std::min(n, e0 + kBlock); ++e) {
      const std::int32_t k = plastic_links_[e];
      const double l = rest_[k];
      const double dl = norm(x_[topo_.b[k]] - x_[topo_.a[k]]) - l;
      const double p = plastic_update(dl, plastic_[k], a, eps_y * l);
      if (p == plastic_[k]) continue;  // within its elastic region: rest length as it was
      plastic_[k] = p;
      kernel_.set_rest(k, l + p);
      changed = true;
    }
  if (changed) ++plastic_version_;
}

void XpbdSheet::mark_unseen() noexcept {
  std::fill(touched_.begin(), touched_.end(), std::uint8_t{0});
  for (int t = 0; t < n_targets_; ++t)
    for (int e = 0; e < 4 && !predicted_targets_.has(t); ++e)
      if (target_stencil_[t].bilinear[e] > 0) touched_[target_stencil_[t].node[e]] = 1;
  const auto ks = keypoint_gain_ > 0 ? keypoint_stencils() : std::span<const SheetPointStencil>{};  // gain 0: they pull nothing
  for (int k = 0; k < static_cast<int>(ks.size()); ++k)
    for (int e = 0; e < 4 && !predicted_keypoints_.has(k); ++e)
      if (ks[k].bilinear[e] > 0) touched_[ks[k].node[e]] = 1;  // the cell it lies in, as a target's
  // A node within kSeenReach grid cells of a touched one is seen too: the nodes between the
  // markers are the observed sheet, only a part with no key-point near it is hidden.
  const Grid& g = grid();
  n_unseen_ = 0;
  for (int j = 0; j < g.h; ++j)
    for (int i = 0; i < g.w; ++i) {
      const int k = g.index(i, j);
      if (pinned_[k]) continue;
      bool near = false;
      for (int b = std::max(0, j - kSeenReach); b <= std::min(g.h - 1, j + kSeenReach) && !near; ++b)
        for (int a = std::max(0, i - kSeenReach); a <= std::min(g.w - 1, i + kSeenReach) && !near; ++a)
          near = touched_[g.index(a, b)] != 0;
      if (!near) unseen_[n_unseen_++] = k;
    }
}

// The free nodes in no depth target's stencil lying within WITHIN_MM of the lowest node and
// under another part of the sheet: a node at least kCoverCells grid cells away from it on the
// sheet, above it by more than two thicknesses, within one node spacing of it across. A node
// hidden only by something else (a hand) is left free: a finger may be sliding it.
void XpbdSheet::mark_hidden_held(double within_mm) noexcept {
  if (n_normal_targets_ == 0) return;  // step_rt emptied the list
  const int n = node_count();
  const Grid& g = grid();
  std::fill(touched_.begin(), touched_.end(), std::uint8_t{0});
  for (int t = 0; t < n_normal_targets_; ++t)
    for (int e = 0; e < 4; ++e)
      if (normal_stencil_[t].bilinear[e] > 0) touched_[normal_stencil_[t].node[e]] = 1;
  double low = 1e300;
  for (int i = 0; i < n; ++i) low = std::min(low, x_[i].z);
  const double across2 = std::max(g.du, g.dv) * std::max(g.du, g.dv);
  const double above = 2.0 * params_.grid.thickness_mm;
  constexpr int kCoverCells = 3;
  for (int i = 0; i < n; ++i) {
    if (touched_[i] || pinned_[i] || x_[i].z > low + within_mm) continue;
    const int ii = i % g.w, ij = i / g.w;
    bool covered = false;
    for (int k = 0; k < n && !covered; ++k) {
      if (std::abs(k % g.w - ii) < kCoverCells && std::abs(k / g.w - ij) < kCoverCells) continue;
      const double dx = x_[k].x - x_[i].x, dy = x_[k].y - x_[i].y;
      covered = x_[k].z - x_[i].z > above && dx * dx + dy * dy <= across2;
    }
    if (covered) hidden_held_[n_hidden_held_++] = i;
  }
}

// After the substep's contacts: the held nodes back to where they were along the table.
void XpbdSheet::hold_hidden() noexcept {
  for (int k = 0; k < n_hidden_held_; ++k) {
    const int i = hidden_held_[k];
    x_[i].x = prev_[i].x;
    x_[i].y = prev_[i].y;
  }
}

// As the speed limit of update_velocities_rt, with the unseen nodes' own limit.
void XpbdSheet::limit_unseen(double dts) noexcept {
  const double cap = unseen_speed_limit_;
  for (int k = 0; k < n_unseen_; ++k) {
    const int i = unseen_[k];
    const double sp2 = dot(v_[i], v_[i]);
    if (sp2 > cap * cap) {
      v_[i] *= cap / std::sqrt(sp2);
      x_[i] = prev_[i] + dts * v_[i];
    }
  }
}

void XpbdSheet::detect_contacts(double dt) noexcept {
  const int n = node_count();
  double vmax2 = 0, moved2 = 0;
  for (int i = 0; i < n; ++i) {
    vmax2 = std::max(vmax2, dot(v_[i], v_[i]));
    const Vec3 d = x_[i] - x_detect_[i];
    moved2 = std::max(moved2, dot(d, d));
  }
  const double push = substep_contacts_ != nullptr ? std::max(0.0, substep_contacts_->max_push_mm(dt)) : 0.0;
  const double frame_move = 1.5 * std::sqrt(vmax2) * dt + push;
  const double frame_margin = std::min(2.0 + frame_move, 30.0);  // the per-frame rule
  const std::uint64_t wv = world_ != nullptr ? world_->version() : 0;
  const bool valid = detect_margin_mm_ >= 0 && world_ == detect_world_ && wv == detect_world_version_ &&
                     2.0 + std::sqrt(moved2) + frame_move <= detect_margin_mm_;
  if (valid) {
    contacts_.select_rt(x_, frame_margin);
    return;
  }
  const double margin = std::min(2.0 + frame_move + kContactSkinMm, 30.0);
  // Layer contacts also a skin's move beside a triangle: nodes slide along the other layer.
  contacts_.detect_rt(x_, world_, margin, margin - frame_margin);
  contacts_.select_rt(x_, frame_margin);
  std::copy(x_.begin(), x_.end(), x_detect_.begin());
  detect_margin_mm_ = margin;
  detect_world_ = world_;
  detect_world_version_ = wv;
  ++detections_;
}

void XpbdSheet::step_rt(double dt) noexcept {
  if (!(dt > 0) || !std::isfinite(dt)) return;
  const SolverParams& sp = params_.solver;
  const int ns = sp.substeps;
  const double dts = dt / ns;
  prepare_frame(dts);
  prepare_targets(dts);
  prepare_normal_targets(dts);
  const bool limit_unseen_nodes = unseen_speed_limit_ > 0 && std::isfinite(unseen_speed_limit_);
  if (limit_unseen_nodes) mark_unseen();
  n_hidden_held_ = 0;
  if (sp.depth_hold_hidden_mm > 0) mark_hidden_held(sp.depth_hold_hidden_mm);
  detect_contacts(dt);

  const double damp = std::max(0.0, 1.0 - sp.damping_per_s * dts);
  const double vcap = sp.max_speed_mm_per_s;
  const int plastic_every = std::max(1, sp.plasticity_every);
  for (int s = 0; s < ns; ++s) {
    // seed 000 Eqs. 1-4 (keypoint_coupling.h)
    (void)coupling_.apply_rt(keypoints(), keypoint_stencils(), keypoint_gain_, dts, x_, v_, pinned_);
    predict_rt(x_, v_, prev_, pin_pos_, keep_, sp.gravity_mm_per_s2, damp, dts, simd_);  // seed 001 Eq. 1
    project_links();
    project_targets();
    project_normal_targets();
    if (substep_contacts_ != nullptr) substep_contacts_->solve_rt(x_, prev_, w_, s, ns, dts);
    if (sp.max_strain > 0) {  // after the external contacts (their holds), before the layers
      const auto hold = substep_contacts_ != nullptr ? substep_contacts_->hold_mass_kg()
                                                     : std::span<const double>{};
      strain_limit_.project_rt(x_, w_, hold, sp.max_strain, sp.strain_limit_sweeps);
    }
    const int every = std::max(1, sp.self_collision_every);
    contacts_.solve_rt(x_, prev_, w_, s % every == every - 1 || s == ns - 1);
    hold_hidden();
    update_velocities_rt(x_, v_, prev_, keep_, dts, vcap, simd_);  // with the speed limit
    if (limit_unseen_nodes) limit_unseen(dts);
    if (links_learn_ && !plastic_links_.empty()) update_plasticity(plastic_every);
  }
  (void)infer_creases_rt();  // solver.crease_strain > 0 only; the next frame re-reads the links
}

}  // namespace crease::sheet
