#include "ode_sheet.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>

#include "plasticity.h"

namespace crease::sheet {
namespace {

constexpr double kLinkDamping = 1e-4;  // kg/s per link (numerical damping of the springs)

}  // namespace

OdeSheet::OdeSheet(const SheetParams& params, int iterations, int steps_per_frame)
    : SheetModel(params), steps_per_frame_(std::max(steps_per_frame, 1)) {
  CollisionWorld init_once;  // dInitODE2 once per process
  (void)init_once;
  ode_world_ = dWorldCreate();
  const Vec3 g = params_.solver.gravity_mm_per_s2;
  dWorldSetGravity(ode_world_, g.x, g.y, g.z);
  dWorldSetQuickStepNumIterations(ode_world_, std::max(iterations, 1));
  dWorldSetAutoDisableFlag(ode_world_, 0);
  const int n = node_count();
  x_ = flat_;
  v_.assign(n, Vec3{});
  prev_ = x_;
  force_.assign(n, Vec3{});
  w_.assign(n, 0.0);
  coupling_.configure(n);
  kinematic_.assign(n, 0);
  bodies_.resize(n);
  for (int i = 0; i < n; ++i) {
    dBodyID b = dBodyCreate(ode_world_);
    dMass m;
    dMassSetSphereTotal(&m, mass_[i], 0.5 * params_.grid.thickness_mm);
    dBodySetMass(b, &m);
    dBodySetPosition(b, x_[i].x, x_[i].y, x_[i].z);
    bodies_[i] = b;
  }
  joints_.resize(link_count());
  for (int k = 0; k < link_count(); ++k) {
    dJointID j = dJointCreateDBall(ode_world_, nullptr);
    dJointAttach(j, bodies_[topo_.a[k]], bodies_[topo_.b[k]]);
    const Vec3 a = x_[topo_.a[k]], b = x_[topo_.b[k]];
    dJointSetDBallAnchor1(j, a.x, a.y, a.z);
    dJointSetDBallAnchor2(j, b.x, b.y, b.z);
    joints_[k] = j;
  }
  layers_.configure(topo_, params_.grid, params_.solver);
}

OdeSheet::~OdeSheet() {
  dWorldDestroy(ode_world_);  // destroys bodies and joints
}

void OdeSheet::set_positions(std::span<const Vec3> pos) noexcept {
  const std::size_t n = std::min(pos.size(), x_.size());
  for (std::size_t i = 0; i < n; ++i) {
    x_[i] = pos[i];
    prev_[i] = pos[i];
    v_[i] = Vec3{};
    dBodySetPosition(bodies_[i], pos[i].x, pos[i].y, pos[i].z);
    dBodySetLinearVel(bodies_[i], 0, 0, 0);
  }
}

// Spring k = 1 / alpha (mN/mm) with damping c: ERP = h k / (h k + c), CFM = 1 / (h k + c).
void OdeSheet::sync_links(double h) noexcept {
  if (synced_version_ == links_version_ && synced_dt_ == h) return;
  for (int k = 0; k < link_count(); ++k) {
    const double alpha = std::max(compliance_[k], 1e-12);
    const double hk = h / alpha;
    dJointSetDBallDistance(joints_[k], rest_[k] + plastic_[k]);
    dJointSetDBallParam(joints_[k], dParamERP, hk / (hk + kLinkDamping));
    dJointSetDBallParam(joints_[k], dParamCFM, 1.0 / (hk + kLinkDamping));
  }
  synced_version_ = links_version_;
  synced_dt_ = h;
}

void OdeSheet::read_bodies() noexcept {
  for (int i = 0; i < node_count(); ++i) {
    const dReal* p = dBodyGetPosition(bodies_[i]);
    const dReal* v = dBodyGetLinearVel(bodies_[i]);
    x_[i] = {p[0], p[1], p[2]};
    v_[i] = {v[0], v[1], v[2]};
  }
}

void OdeSheet::substep(double dts) noexcept {
  const int n = node_count();
  const SolverParams& sp = params_.solver;
  // Pins: kinematic bodies moved to their targets.
  for (int i = 0; i < n; ++i) {
    if (pinned_[i] != kinematic_[i]) {
      if (pinned_[i]) dBodySetKinematic(bodies_[i]);
      else dBodySetDynamic(bodies_[i]);
      kinematic_[i] = pinned_[i];
    }
    if (pinned_[i]) {
      const Vec3 d = (1.0 / dts) * (pin_pos_[i] - x_[i]);
      dBodySetLinearVel(bodies_[i], d.x, d.y, d.z);
    }
    w_[i] = pinned_[i] ? 0.0 : 1.0 / mass_[i];
  }
  // seed 000 Eqs. 1-4 (keypoint_coupling.h, as in the XPBD backend): the bodies of the nodes
  // it moved take their new velocities.
  const auto moved = coupling_.apply_rt(keypoints(), keypoint_stencils(), keypoint_gain_, dts, x_, v_, pinned_);
  for (const std::int32_t i : moved) dBodySetLinearVel(bodies_[i], v_[i].x, v_[i].y, v_[i].z);
  for (int i = 0; i < n; ++i) prev_[i] = x_[i];
  dWorldQuickStep(ode_world_, dts);
  read_bodies();
  // Damping and the speed limit, as in the XPBD backend.
  const double damp = std::max(0.0, 1.0 - sp.damping_per_s * dts);
  for (int i = 0; i < n; ++i) {
    if (pinned_[i]) {
      x_[i] = pin_pos_[i];
      v_[i] = Vec3{};
    } else {
      Vec3 v = damp * v_[i];
      const double s2 = dot(v, v), cap = sp.max_speed_mm_per_s;
      if (s2 > cap * cap) v *= cap / std::sqrt(s2);
      v_[i] = v;
    }
  }
  // seed 001 Eq. 4 (zero-length target springs) on the stepped positions, as in XPBD, with
  // the velocity change that the move implies.
  const double at = sp.target_compliance_m_per_n / (dts * dts);
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
    for (int e = 0; e < 4; ++e) {
      const Vec3 dx = (w_[s.node[e]] * s.bilinear[e]) * err;
      x_[s.node[e]] -= dx;
      v_[s.node[e]] -= (1.0 / dts) * dx;
    }
  }
  // Residual penetration of shapes and layers: the contact projection, then velocities
  // corrected by the change.
  for (int i = 0; i < n; ++i) force_[i] = x_[i];
  layers_.solve_rt(x_, prev_, w_);
  for (int i = 0; i < n; ++i) v_[i] += (1.0 / dts) * (x_[i] - force_[i]);
  for (int i = 0; i < n; ++i) {
    dBodySetPosition(bodies_[i], x_[i].x, x_[i].y, x_[i].z);
    dBodySetLinearVel(bodies_[i], v_[i].x, v_[i].y, v_[i].z);
  }
  // Plasticity (seed 001 III.C) on the joints' rest lengths.
  if (sp.plasticity_rate > 0 && links_learn_) {
    for (int k = 0; k < link_count(); ++k) {
      if (sp.plastic_bending_only && topo_.kind[k] != LinkKind::bending) continue;
      const double l = rest_[k];
      const double dl = norm(x_[topo_.b[k]] - x_[topo_.a[k]]) - l;
      const double p = plastic_update(dl, plastic_[k], sp.plasticity_rate, sp.yield_strain * l);
      if (p != plastic_[k]) {
        plastic_[k] = p;
        ++plastic_version_;
        dJointSetDBallDistance(joints_[k], l + p);
      }
    }
  }
}

void OdeSheet::step_rt(double dt) noexcept {
  if (!(dt > 0) || !std::isfinite(dt)) return;
  const int ns = steps_per_frame_;
  const double dts = dt / ns;
  sync_links(dts);
  double vmax = 0;
  for (const Vec3& v : v_) vmax = std::max(vmax, norm(v));
  layers_.detect_rt(x_, world_, std::min(2.0 + 1.5 * vmax * dt, 30.0));
  for (int s = 0; s < ns; ++s) substep(dts);
  (void)infer_creases_rt();  // solver.crease_strain > 0 only
}

}  // namespace crease::sheet
