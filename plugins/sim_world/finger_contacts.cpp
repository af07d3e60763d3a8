#include "plugins/sim_world/finger_contacts.h"

#include <algorithm>
#include <cmath>

#include "plugins/sim_world/table_contact.h"

namespace crease::world {
namespace {

using sheet::cross;
using sheet::dot;
using sheet::norm;
using sheet::normalized;

}  // namespace

void FingerContacts::configure(const sheet::SheetModel& sheet, std::span<const WorldShape> shapes, const Config& cfg) {
  cfg_ = cfg;
  shapes_ = shapes.data();
  const int shape_count = static_cast<int>(shapes.size());
  sheet_ = &sheet;
  const sheet::Grid& g = sheet.grid();
  grid_w_ = g.w;
  grid_h_ = g.h;
  du_ = g.du;
  dv_ = g.dv;
  patch_reach_ = 0.5 * std::hypot(du_, dv_);
  half_thickness_ = 0.5 * sheet.params().grid.thickness_mm;
  const int n = sheet.node_count();
  const double kg_per_mm2 = sheet.params().grid.areal_density_g_per_m2 * 1e-9;
  node_area_mm2_.resize(n);
  for (int i = 0; i < n; ++i) node_area_mm2_[i] = sheet.node_masses_kg()[i] / kg_per_mm2;
  slot_of_node_.assign(n, -1);
  hold_kg_.assign(n, 0.0);
  touched_.resize(n);
  shape_near_.assign(shape_count, 0);
  springback_mm_.assign(shape_count, 0.0);
  bound_reach_mm_.resize(shape_count);
  for (int k = 0; k < shape_count; ++k)
    bound_reach_mm_[k] = core_grow(shapes[k].geom) + patch_reach_;
  pose_now_.resize(shape_count);
  pose_before_.resize(shape_count);
  load_.assign(shape_count, ShapeLoad{});
  residual_.resize(static_cast<std::size_t>(n) * kMaxShapesPerNode);
  cell_start_.assign(kMaxCells * kMaxCells + 1, 0);
  cell_nodes_.assign(n, 0);
  cell_of_.assign(n, 0);
  cell_points_.assign(n, Vec3{});
  n_shapes_ = shape_count;
}

void FingerContacts::begin_step_rt(std::span<const Vec3> x, std::span<const Vec3> v, double dt) noexcept {
  const WorldShape* shapes = shapes_;
  for (int k = 0; k < n_touched_; ++k) {
    slot_of_node_[touched_[k].node] = -1;
    hold_kg_[touched_[k].node] = 0.0;
  }
  n_touched_ = 0;
  max_push_mm_ = 0;
  for (int s = 0; s < n_shapes_; ++s) {
    load_[s] = ShapeLoad{};
    shape_near_[s] = 0;
  }
  if (!cfg_.hand_contacts) return;

  const int n = static_cast<int>(x.size());
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  double v2 = 0;
  for (int i = 0; i < n; ++i) {
    lo = {std::min(lo.x, x[i].x), std::min(lo.y, x[i].y), std::min(lo.z, x[i].z)};
    hi = {std::max(hi.x, x[i].x), std::max(hi.y, x[i].y), std::max(hi.z, x[i].z)};
    v2 = std::max(v2, dot(v[i], v[i]));
  }
  const double reach = half_thickness_ + cfg_.margin_mm + std::sqrt(v2) * dt;
  // Buckets in x, y.
  const double cx = std::max(8.0, (hi.x - lo.x) / kMaxCells + 1e-9), cy = std::max(8.0, (hi.y - lo.y) / kMaxCells + 1e-9);
  const int nx = std::min(kMaxCells, static_cast<int>((hi.x - lo.x) / cx) + 1);
  const int ny = std::min(kMaxCells, static_cast<int>((hi.y - lo.y) / cy) + 1);
  const double inv_cx = 1.0 / cx, inv_cy = 1.0 / cy;
  auto cell_x = [&](double px) {
    return std::clamp(static_cast<int>((px - lo.x) * inv_cx), 0, nx - 1);
  };
  auto cell_y = [&](double py) {
    return std::clamp(static_cast<int>((py - lo.y) * inv_cy), 0, ny - 1);
  };
  std::fill(cell_start_.begin(), cell_start_.begin() + nx * ny + 1, 0);
  for (int i = 0; i < n; ++i) {
    cell_of_[i] = cell_y(x[i].y) * nx + cell_x(x[i].x);
    ++cell_start_[cell_of_[i] + 1];
  }
  for (int c = 0; c < nx * ny; ++c) cell_start_[c + 1] += cell_start_[c];
  for (int i = 0; i < n; ++i) {
    const int e = cell_start_[cell_of_[i]]++;
    cell_nodes_[e] = i;
    cell_points_[e] = x[i];
  }
  for (int c = nx * ny; c > 0; --c) cell_start_[c] = cell_start_[c - 1];
  cell_start_[0] = 0;

  for (int s = 0; s < n_shapes_; ++s) {
    const WorldShape& sh = shapes[s];
    double bl[3], bh[3];
    const double t0[3] = {sh.pose0.t.x, sh.pose0.t.y, sh.pose0.t.z}, t1[3] = {sh.pose1.t.x, sh.pose1.t.y, sh.pose1.t.z};
    const double reach_s = reach + springback_mm_[s];
    for (int a = 0; a < 3; ++a) {
      const double e0 = half_extent(sh.geom, sh.pose0, a), e1 = half_extent(sh.geom, sh.pose1, a);
      bl[a] = std::min(t0[a] - e0, t1[a] - e1) - reach_s;
      bh[a] = std::max(t0[a] + e0, t1[a] + e1) + reach_s;
    }
    if (bh[0] < lo.x || bl[0] > hi.x || bh[1] < lo.y || bl[1] > hi.y || bh[2] < lo.z || bl[2] > hi.z) continue;
    shape_near_[s] = 1;
    // How far the shape's surface may move this step: its centre plus its turn at its extent.
    const double d = std::fabs(sh.quat0[0] * sh.quat1[0] + sh.quat0[1] * sh.quat1[1] + sh.quat0[2] * sh.quat1[2] +
                               sh.quat0[3] * sh.quat1[3]);
    const double turn = 2.0 * std::acos(std::min(1.0, d));
    const double radius = std::max({half_extent(sh.geom, sh.pose1, 0), half_extent(sh.geom, sh.pose1, 1),
                                    half_extent(sh.geom, sh.pose1, 2)}) * 1.7320508075688772;
    const double sweep = norm(sh.pose1.t - sh.pose0.t) + turn * radius;
    max_push_mm_ = std::max(max_push_mm_, sweep);
    const int ix0 = cell_x(bl[0]), ix1 = cell_x(bh[0]), iy0 = cell_y(bl[1]), iy1 = cell_y(bh[1]);
    // A row's buckets ix0..ix1 lie contiguous in bucket order.
    for (int iy = iy0; iy <= iy1; ++iy) {
      for (int e = cell_start_[iy * nx + ix0]; e < cell_start_[iy * nx + ix1 + 1]; ++e) {
        const Vec3& p = cell_points_[e];
        if (p.x < bl[0] || p.x > bh[0] || p.y < bl[1] || p.y > bh[1] || p.z < bl[2] || p.z > bh[2])
          continue;
        // A lower bound on the patch's distance from the shape (exact but for a cylinder).
        if (patch_distance_bound(s, sh.pose1.inverse_apply(p)) > reach_s + sweep) continue;
        const int node = cell_nodes_[e];
        int slot = slot_of_node_[node];
        if (slot < 0) {
          slot = n_touched_++;
          slot_of_node_[node] = slot;
          Touched& t = touched_[slot];
          t.node = node;
          t.n_shapes = 0;
          const int i = node % grid_w_, j = node / grid_w_;
          const Vec3 du =
              x[j * grid_w_ + std::min(i + 1, grid_w_ - 1)] - x[j * grid_w_ + std::max(i - 1, 0)];
          const Vec3 dv =
              x[std::min(j + 1, grid_h_ - 1) * grid_w_ + i] - x[std::max(j - 1, 0) * grid_w_ + i];
          t.eu = normalized(du);
          t.ev = normalized(dv - dot(dv, t.eu) * t.eu);
          t.en = cross(t.eu, t.ev);
          t.ulo = i > 0 ? -0.5 * du_ : 0.0;
          t.uhi = i < grid_w_ - 1 ? 0.5 * du_ : 0.0;
          t.vlo = j > 0 ? -0.5 * dv_ : 0.0;
          t.vhi = j < grid_h_ - 1 ? 0.5 * dv_ : 0.0;
          t.area_mm2 = node_area_mm2_[node];
          t.support = -1;
        }
        Touched& t = touched_[slot];
        if (t.n_shapes >= kMaxShapesPerNode) {
          ++dropped_;
          continue;
        }
        t.shape[t.n_shapes++] = s;
      }
    }
  }
  find_supports_rt(x, nx, ny);
}

bool FingerContacts::on_table(Vec3 p) const noexcept {
  return p.z <= cfg_.table_height_mm + 2.0 * half_thickness_ &&
         over_extent(p, cfg_.table_extent_mm);
}

void FingerContacts::find_supports_rt(std::span<const Vec3> x, int nx, int ny) noexcept {
  // A touched node a layer up (not itself on the table) rests on the node of another layer
  // nearest under it in x, y: within 0.75 of the spacing across (the half diagonal of a cell:
  // one is always found on a layer), one to four thicknesses lower
  // (or a gap of kInactiveReachMm), at least 3 grid cells away on the sheet, lying on the table.
  const double across = 0.75 * std::max(du_, dv_), thick = 2.0 * half_thickness_;
  for (int k = 0; k < n_touched_; ++k) {
    Touched& t = touched_[k];
    const Vec3 p = x[t.node];
    if (on_table(p)) continue;
    const int ti = t.node % grid_w_, tj = t.node / grid_w_;
    const int ix = cell_of_[t.node] % nx, iy = cell_of_[t.node] / nx;
    double best = across * across;
    const int bx0 = std::max(0, ix - 1), bx1 = std::min(nx - 1, ix + 1);
    for (int by = std::max(0, iy - 1); by <= std::min(ny - 1, iy + 1); ++by)
      for (int e = cell_start_[by * nx + bx0]; e < cell_start_[by * nx + bx1 + 1]; ++e) {
        const Vec3& q = cell_points_[e];
        const double dz = p.z - q.z, dx = p.x - q.x, dy = p.y - q.y, d2 = dx * dx + dy * dy;
        if (d2 >= best || dz < 0.5 * thick || dz > 4.0 * thick + kInactiveReachMm || !on_table(q))
          continue;
        const int b = cell_nodes_[e];
        if (std::abs(b % grid_w_ - ti) + std::abs(b / grid_w_ - tj) < 3) continue;
        best = d2;
        t.support = b;
      }
  }
}

double FingerContacts::max_push_mm(double) const noexcept { return n_touched_ > 0 ? max_push_mm_ : 0.0; }

double FingerContacts::patch_distance_bound(int shape, Vec3 x_local) const noexcept {
  return norm(closest_core_local(shapes_[shape].geom, x_local) - x_local) - bound_reach_mm_[shape];
}

Vec3 FingerContacts::deepest_patch_point(const WorldShape& s, const Touched& t,
                                         const Local& l) noexcept {
  Vec3 q = l.x;
  double last_u = 0, last_v = 0;
  for (int it = 0; it < 3; ++it) {
    const Vec3 d = closest_core_local(s.geom, q) - l.x;
    const double pu = std::clamp(dot(d, l.eu), t.ulo, t.uhi),
                 pv = std::clamp(dot(d, l.ev), t.vlo, t.vhi);
    if (it > 0 && pu == last_u && pv == last_v) break;  // a fixed point: the rounds left repeat it
    last_u = pu, last_v = pv;
    q = l.x + pu * l.eu + pv * l.ev;
  }
  return q;
}

FingerContacts::Geometry FingerContacts::geometry(const WorldShape& s, const Pose& pose,
                                                  const Touched& t, const Local& l) const noexcept {
  const Vec3 q = deepest_patch_point(s, t, l);
  const SurfacePoint sp = closest_surface_local(s.geom, q);
  const Vec3 normal = pose.rotate(sp.normal);
  Geometry g;
  g.point = pose.apply(sp.point);
  g.pen = half_thickness_ - sp.distance_mm;
  const double c = dot(normal, t.en);
  constexpr double kFaceOn = 0.5;  // cos 60 deg
  if (std::fabs(c) >= kFaceOn) {
    g.n = c > 0 ? t.en : -1.0 * t.en;
    g.pen /= std::fabs(c);
  } else {
    g.n = normal;
  }
  return g;
}

void FingerContacts::measure_rt(std::span<const Pose> poses, std::span<const Vec3> x,
                                bool gaps) noexcept {
  n_residual_ = 0;
  const double held_z = cfg_.table_height_mm + 5.0 * half_thickness_;  // on the table, or on a layer on it
  for (int k = 0; k < n_touched_; ++k) {
    const Touched& t = touched_[k];
    const Vec3 p = x[t.node];
    const bool held = p.z <= held_z && over_extent(p, cfg_.table_extent_mm);
    // A node nothing holds lists only a pinch: with no two fingers near it, nothing (in
    // crease-bench world's scenes 31 % of the pairs the balance's measure looked at, each a
    // patch search).
    if (!held && !may_pinch(t)) continue;
    // A pair is listed only within kGapMm + its springback; most candidates are further (the
    // candidates reach the step's sweep as well). The lower bound of gather_rt rules those out
    // before the deepest patch point is sought; a pair ruled out is given a depth below every
    // listed pair's threshold on this node, so that it neither is listed nor wins an exit.
    // Without gaps, a node no shape can press is passed over: a pressing contact, or a pinch
    // of positive depth, needs one shape pressing it.
    Vec3 xl[kMaxShapesPerNode];
    double deepest_bound[kMaxShapesPerNode];  // the most the pair's depth can be (mm)
    double springback_max = 0, may_press = -1e300;
    for (int s = 0; s < t.n_shapes; ++s) {
      springback_max = std::max(springback_max, springback_mm_[t.shape[s]]);
      xl[s] = poses[t.shape[s]].inverse_apply(p);
      deepest_bound[s] = half_thickness_ - patch_distance_bound(t.shape[s], xl[s]);
      may_press = std::max(may_press, deepest_bound[s]);
    }
    if (!gaps && may_press <= 0) continue;
    const double far_below = -(kGapMm + springback_max);
    Geometry geo[kMaxShapesPerNode];
    bool used[kMaxShapesPerNode] = {};
    for (int s = 0; s < t.n_shapes; ++s) {
      if (deepest_bound[s] <= far_below) {
        geo[s] = Geometry{};
        geo[s].pen = -1e300;
        continue;
      }
      const Pose& pose = poses[t.shape[s]];
      geo[s] = geometry(shapes_[t.shape[s]], pose, t, to_local(pose, t, xl[s]));
    }
    for (int s = 0; s < t.n_shapes; ++s)  // one contact per rigid body (see gather_rt)
      for (int o = 0; o < t.n_shapes; ++o) {
        const WorldShape &a = shapes_[t.shape[s]], &b = shapes_[t.shape[o]];
        if (o != s && !used[o] && a.side == b.side && a.body == b.body && better_exit(geo[o].pen, geo[s].pen))
          used[s] = true;
      }
    for (int s = 0; s < t.n_shapes; ++s) {
      if (used[s] || geo[s].pen <= -(kGapMm + springback_mm_[t.shape[s]])) continue;
      const WorldShape& a = shapes_[t.shape[s]];
      const double ka = a.stiffness_n_per_mm3 * t.area_mm2;
      if (n_residual_ >= static_cast<int>(residual_.size())) {
        ++dropped_;
        return;
      }
      Residual& r = residual_[n_residual_];
      if (held) {
        r = {t.shape[s], geo[s].point, geo[s].n, -1, {}, {}, geo[s].pen, ka};
        if (gaps || r.depth_mm > 0) ++n_residual_;
        continue;
      }
      // Not held: a pinch needs a second shape of the same hand on the other side.
      for (int o = s + 1; o < t.n_shapes; ++o) {
        const WorldShape& b = shapes_[t.shape[o]];
        if (used[o] || !pinch_pair(a, b) || geo[o].pen <= -(kGapMm + springback_mm_[t.shape[o]]) ||
            dot(geo[s].n, geo[o].n) > -0.3)
          continue;
        const double kb = b.stiffness_n_per_mm3 * t.area_mm2;
        r = {t.shape[s], geo[s].point, geo[s].n, t.shape[o], geo[o].point, geo[o].n, geo[s].pen + geo[o].pen,
             ka * kb / (ka + kb)};
        if (gaps || r.depth_mm > 0) ++n_residual_;
        used[s] = used[o] = true;
        break;
      }
    }
  }
}

bool FingerContacts::may_pinch(const Touched& t) const noexcept {
  for (int s = 0; s < t.n_shapes; ++s)
    for (int o = s + 1; o < t.n_shapes; ++o)
      if (pinch_pair(shapes_[t.shape[s]], shapes_[t.shape[o]])) return true;
  return false;
}

void FingerContacts::end_step_rt(std::span<const Vec3> x) noexcept {
  for (int s = 0; s < n_shapes_; ++s) pose_now_[s] = shapes_[s].pose1;
  measure_rt(pose_now_, x, false);
  for (int k = 0; k < n_residual_; ++k) {
    if (residual_[k].depth_mm <= 0) continue;
    ++load_[residual_[k].shape].nodes;
    if (residual_[k].shape2 >= 0) ++load_[residual_[k].shape2].nodes;
  }
}

}  // namespace crease::world
