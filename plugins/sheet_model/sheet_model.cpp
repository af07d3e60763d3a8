#include "sheet_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "core/assert.h"

namespace crease::sheet {
namespace {

// Parameters come from a plugin's configuration (or a test's): bad input, ConfigError.
void require(bool ok, const char* key, const char* why) {
  if (!ok) throw crease::ConfigError(std::string("sheet_model: ") + key + ": " + why);
}

}  // namespace

SheetModel::SheetModel(const SheetParams& params)
    : params_(params), topo_(build_topology(params.grid, params.topology)) {
  const SolverParams& s = params_.solver;
  require(s.substeps >= 1 && s.substeps <= 1000, "solver.substeps", "must be in [1, 1000]");
  require(s.max_strain >= 0 && s.max_strain <= 1, "solver.max_strain", "must be in [0, 1]");
  require(s.strain_limit_sweeps >= 1 && s.strain_limit_sweeps <= 100, "solver.strain_limit_sweeps",
          "must be in [1, 100]");
  require(s.stiffness > 0 && s.stiffness <= 1, "solver.stiffness", "must be in (0, 1]");
  require(s.crease_stiffness > 0 && s.crease_stiffness <= 1, "solver.crease_stiffness",
          "must be in (0, 1]");
  require(s.compliance_structural_m_per_n >= 0 && s.compliance_bending_m_per_n >= 0,
          "solver.compliance_*_m_per_n", "must be >= 0");
  require(s.plasticity_rate >= 0 && s.plasticity_rate < 1, "solver.plasticity_rate",
          "must be in [0, 1)");
  require(s.yield_strain >= 0, "solver.yield_strain", "must be >= 0");
  require(s.plasticity_every >= 1, "solver.plasticity_every", "must be >= 1");
  require(s.crease_strain >= 0, "solver.crease_strain", "must be >= 0");
  require(s.damping_per_s >= 0, "solver.damping_per_s", "must be >= 0");
  require(params_.grid.areal_density_g_per_m2 > 0, "grid.areal_density_g_per_m2", "must be > 0");
  require(params_.grid.thickness_mm > 0, "grid.thickness_mm", "must be > 0");

  const Grid& g = topo_.grid;
  const int n = g.count();
  mass_.assign(n, 0.0);
  flat_.resize(n);
  // Area-lumped masses: each node carries a quarter of each adjacent cell.
  const double cell_kg = params_.grid.areal_density_g_per_m2 * 1e-3 * (g.du * 1e-3) * (g.dv * 1e-3);
  for (int j = 0; j < g.h; ++j) {
    for (int i = 0; i < g.w; ++i) {
      const int cells_u = (i == 0 || i == g.w - 1) ? 1 : 2;
      const int cells_v = (j == 0 || j == g.h - 1) ? 1 : 2;
      mass_[g.index(i, j)] = 0.25 * cell_kg * cells_u * cells_v;
      flat_[g.index(i, j)] = flat_position(g.sheet_of(g.index(i, j)));
    }
  }
  const int m = topo_.link_count();
  rest_.assign(m, 0.0);
  plastic_.assign(m, 0.0);
  stiffness_.assign(m, s.stiffness);
  compliance_.assign(m, 0.0);
  inferred_.assign(m, 0);
  for (int k = 0; k < m; ++k) rest_[k] = norm(flat_[topo_.b[k]] - flat_[topo_.a[k]]);
  pinned_.assign(n, 0);
  pin_pos_.assign(n, Vec3{});
  keypoints_.resize(kMaxKeypoints);
  keypoint_stencil_.resize(kMaxKeypoints);
  targets_.resize(kMaxTargets);
  target_stencil_.resize(kMaxTargets);
  normal_targets_.resize(kMaxTargets);
  normal_stencil_.resize(kMaxTargets);
  keypoint_gain_ = s.keypoint_gain_per_s;
  restore_link_stiffness();
  saved_rest_ = rest_;
  saved_plastic_ = plastic_;
  saved_stiffness_ = stiffness_;
  saved_compliance_ = compliance_;
  saved_inferred_ = inferred_;
  saved_creases_ = creases_;
  saved_version_ = links_version_;
}

Vec3 SheetModel::flat_position(Vec2 p) const noexcept {
  const Vec3& o = params_.grid.origin_mm;
  const double a = params_.grid.turn_deg * std::numbers::pi / 180.0, c = std::cos(a), s = std::sin(a);
  return {o.x + c * p.u + s * p.v, o.y + s * p.u - c * p.v, o.z};
}

void SheetModel::reset_rt() noexcept {
  creases_.clear();
  std::fill(inferred_.begin(), inferred_.end(), std::uint8_t{0});
  n_inferred_ = 0;
  for (int k = 0; k < link_count(); ++k) {
    rest_[k] = norm(flat_[topo_.b[k]] - flat_[topo_.a[k]]);
    plastic_[k] = 0.0;
  }
  std::fill(pinned_.begin(), pinned_.end(), std::uint8_t{0});
  clear_inputs();
  restore_link_stiffness();
  set_positions(flat_);
}

double SheetModel::link_base_compliance(int k) const noexcept {
  return topo_.kind[k] == LinkKind::structural ? params_.solver.compliance_structural_m_per_n
                                               : params_.solver.compliance_bending_m_per_n;
}

void SheetModel::restore_link_stiffness() noexcept {
  const int m = link_count();
  const Grid& g = topo_.grid;
  for (int k = 0; k < m; ++k) {
    double s = inferred_[k] ? params_.solver.crease_stiffness : params_.solver.stiffness;
    const Vec2 p = g.sheet_of(topo_.a[k]), q = g.sheet_of(topo_.b[k]);
    for (int c = 0; c < CreaseSet::kCapacity; ++c) {
      if (creases_.used(c) && segments_cross(p, q, creases_.line(c).a, creases_.line(c).b)) {
        s = params_.solver.crease_stiffness;
        break;
      }
    }
    stiffness_[k] = s;
    compliance_[k] = link_base_compliance(k) / s;
  }
  ++links_version_;
}

int SheetModel::add_crease(CreaseLine line) noexcept {
  const int id = creases_.add(line);
  if (id >= 0) restore_link_stiffness();
  return id;
}

int SheetModel::infer_creases_rt() noexcept {
  const double limit = params_.solver.crease_strain;
  if (!(limit > 0) || !links_learn_) return 0;
  const auto x = positions();
  const double cs = params_.solver.crease_stiffness;
  int cut = 0;
  for (int k = 0; k < link_count(); ++k) {
    if (inferred_[k] || topo_.kind[k] != LinkKind::bending) continue;
    const double l = rest_[k] + plastic_[k];
    if (!(l > 0) || std::fabs(norm(x[topo_.b[k]] - x[topo_.a[k]]) - l) <= limit * l) continue;
    inferred_[k] = 1;
    if (stiffness_[k] > cs) {
      stiffness_[k] = cs;
      compliance_[k] = link_base_compliance(k) / cs;
    }
    ++cut;
  }
  if (cut > 0) {
    n_inferred_ += cut;
    ++links_version_;
  }
  return cut;
}

bool SheetModel::remove_crease(int id) noexcept {
  if (!creases_.remove(id)) return false;
  restore_link_stiffness();
  return true;
}

void SheetModel::memorize_all() noexcept {
  const auto x = positions();
  for (int k = 0; k < link_count(); ++k) {
    rest_[k] = norm(x[topo_.b[k]] - x[topo_.a[k]]);
    plastic_[k] = 0.0;
  }
  ++links_version_;
}

int SheetModel::memorize_region(Region r) noexcept {
  const auto x = positions();
  const Grid& g = topo_.grid;
  auto inside = [&r](Vec2 p) {
    return p.u >= r.min.u && p.u <= r.max.u && p.v >= r.min.v && p.v <= r.max.v;
  };
  int n = 0;
  for (int k = 0; k < link_count(); ++k) {
    if (inside(g.sheet_of(topo_.a[k])) && inside(g.sheet_of(topo_.b[k]))) {
      rest_[k] = norm(x[topo_.b[k]] - x[topo_.a[k]]);
      plastic_[k] = 0.0;
      ++n;
    }
  }
  ++links_version_;
  return n;
}

SheetPointStencil SheetModel::stencil(Vec2 p) const noexcept {
  const Grid& g = topo_.grid;
  const double gu = std::clamp(p.u / g.du, 0.0, double(g.w - 1));
  const double gv = std::clamp(p.v / g.dv, 0.0, double(g.h - 1));
  const int i0 = std::min(int(gu), g.w - 2), j0 = std::min(int(gv), g.h - 2);
  const double fu = gu - i0, fv = gv - j0;
  SheetPointStencil s;
  const int di[4] = {0, 1, 0, 1}, dj[4] = {0, 0, 1, 1};
  for (int c = 0; c < 4; ++c) {
    s.node[c] = g.index(i0 + di[c], j0 + dj[c]);
    s.bilinear[c] = (di[c] ? fu : 1 - fu) * (dj[c] ? fv : 1 - fv);
    const double du = fu - di[c], dv = fv - dj[c];
    s.alpha[c] = std::max(1.0 - std::sqrt(du * du + dv * dv), 0.0);
  }
  return s;
}

Vec3 SheetModel::interpolate(Vec2 p) const noexcept {
  const SheetPointStencil s = stencil(p);
  const auto x = positions();
  Vec3 r;
  for (int c = 0; c < 4; ++c) r += s.bilinear[c] * x[s.node[c]];
  return r;
}

int SheetModel::set_keypoints(std::span<const KeypointObs> k) noexcept {
  n_keypoints_ = 0;
  for (const KeypointObs& o : k) {
    if (n_keypoints_ >= kMaxKeypoints) break;
    if (!is_finite(o.world_mm) || !std::isfinite(o.sheet_mm.u) || !std::isfinite(o.sheet_mm.v))
      continue;
    keypoints_[n_keypoints_] = o;
    keypoint_stencil_[n_keypoints_] = stencil(o.sheet_mm);
    ++n_keypoints_;
  }
  return n_keypoints_;
}

int SheetModel::set_normal_targets(std::span<const NormalTarget> t) noexcept {
  n_normal_targets_ = 0;
  for (const NormalTarget& o : t) {
    if (n_normal_targets_ >= kMaxTargets) break;
    if (!is_finite(o.world_mm) || !std::isfinite(o.sheet_mm.u) || !std::isfinite(o.sheet_mm.v) ||
        !(o.weight > 0.0 && o.weight <= 1.0))
      continue;
    normal_targets_[n_normal_targets_] = o;
    normal_stencil_[n_normal_targets_] = stencil(o.sheet_mm);
    ++n_normal_targets_;
  }
  return n_normal_targets_;
}

int SheetModel::set_targets(std::span<const TargetPoint> t) noexcept {
  n_targets_ = 0;
  for (const TargetPoint& o : t) {
    if (n_targets_ >= kMaxTargets) break;
    if (!is_finite(o.world_mm) || !std::isfinite(o.sheet_mm.u) || !std::isfinite(o.sheet_mm.v))
      continue;
    targets_[n_targets_] = o;
    target_stencil_[n_targets_] = stencil(o.sheet_mm);
    ++n_targets_;
  }
  return n_targets_;
}

void SheetModel::pin(int node, Vec3 world_mm) noexcept {
  if (node < 0 || node >= node_count() || !is_finite(world_mm)) return;
  if (pinned_[node] == 0) ++links_version_;  // inverse masses change
  pinned_[node] = 1;
  pin_pos_[node] = world_mm;
}

void SheetModel::unpin(int node) noexcept {
  if (node < 0 || node >= node_count() || pinned_[node] == 0) return;
  pinned_[node] = 0;
  ++links_version_;  // inverse masses change
}

void SheetModel::compute_normals(std::span<Vec3> out) const noexcept {
  const auto x = positions();
  const int n = std::min<int>(node_count(), int(out.size()));
  for (int i = 0; i < n; ++i) out[i] = Vec3{};
  const auto& t = topo_.tri;
  for (std::size_t k = 0; k + 2 < t.size(); k += 3) {
    // Triangles wind along +u then +v: their cross product points along sheet z (into the
    // paper); the printed face's outward normal is its opposite.
    const Vec3 c = cross(x[t[k + 1]] - x[t[k]], x[t[k + 2]] - x[t[k]]);
    for (int e = 0; e < 3; ++e)
      if (t[k + e] < n) out[t[k + e]] -= c;
  }
  for (int i = 0; i < n; ++i) out[i] = normalized(out[i]);
}

void SheetModel::compute_strains(std::span<double> out) const noexcept {
  const auto x = positions();
  const int m = std::min<int>(link_count(), int(out.size()));
  for (int k = 0; k < m; ++k) {
    const double l = rest_[k] + plastic_[k];
    out[k] = l > 0 ? (norm(x[topo_.b[k]] - x[topo_.a[k]]) - l) / l : 0.0;
  }
}

void SheetModel::save_links_rt() noexcept {
  if (saved_version_ != links_version_) {
    std::copy(rest_.begin(), rest_.end(), saved_rest_.begin());
    std::copy(stiffness_.begin(), stiffness_.end(), saved_stiffness_.begin());
    std::copy(compliance_.begin(), compliance_.end(), saved_compliance_.begin());
    std::copy(plastic_.begin(), plastic_.end(), saved_plastic_.begin());
    std::copy(inferred_.begin(), inferred_.end(), saved_inferred_.begin());
    saved_n_inferred_ = n_inferred_;
    saved_creases_ = creases_;
    saved_version_ = links_version_;
    saved_plastic_version_ = plastic_version_;
  } else if (saved_plastic_version_ != plastic_version_) {
    std::copy(plastic_.begin(), plastic_.end(), saved_plastic_.begin());
    saved_plastic_version_ = plastic_version_;
  }
}

void SheetModel::restore_links_rt() noexcept {
  std::copy(saved_rest_.begin(), saved_rest_.end(), rest_.begin());
  std::copy(saved_stiffness_.begin(), saved_stiffness_.end(), stiffness_.begin());
  std::copy(saved_compliance_.begin(), saved_compliance_.end(), compliance_.begin());
  std::copy(saved_plastic_.begin(), saved_plastic_.end(), plastic_.begin());
  std::copy(saved_inferred_.begin(), saved_inferred_.end(), inferred_.begin());
  n_inferred_ = saved_n_inferred_;
  creases_ = saved_creases_;
  ++links_version_;  // backends re-read rest lengths and compliances
  saved_version_ = links_version_;
  saved_plastic_version_ = plastic_version_;
}

bool SheetModel::state_finite() const noexcept {
  for (const Vec3& p : positions())
    if (!is_finite(p)) return false;
  for (const Vec3& v : velocities())
    if (!is_finite(v)) return false;
  return true;
}

}  // namespace crease::sheet
