// FingerContacts' substep solve (finger_contacts.h): each touched node's contacts gathered,
// solved as one block (normal, then friction), and the press carried to the layer under it.
#include <algorithm>
#include <cmath>

#include "plugins/sim_world/finger_contacts.h"
#include "plugins/sim_world/table_contact.h"

namespace crease::world {
namespace {

using sheet::cross;
using sheet::dot;
using sheet::norm;

constexpr int kMaxNodeContacts = FingerContacts::kMaxNodeContacts;

// Solves A x = b for the m x m leading block (partial pivoting). False if singular.
bool solve_small(double a[kMaxNodeContacts][kMaxNodeContacts], double b[kMaxNodeContacts],
                 int m) noexcept {
  for (int c = 0; c < m; ++c) {
    int piv = c;
    for (int r = c + 1; r < m; ++r)
      if (std::fabs(a[r][c]) > std::fabs(a[piv][c])) piv = r;
    if (!(std::fabs(a[piv][c]) > 0)) return false;
    if (piv != c) {
      for (int k = 0; k < m; ++k) std::swap(a[c][k], a[piv][k]);
      std::swap(b[c], b[piv]);
    }
    for (int r = c + 1; r < m; ++r) {
      const double f = a[r][c] / a[c][c];
      for (int k = c; k < m; ++k) a[r][k] -= f * a[c][k];
      b[r] -= f * b[c];
    }
  }
  for (int c = m - 1; c >= 0; --c) {
    double s = b[c];
    for (int k = c + 1; k < m; ++k) s -= a[c][k] * b[k];
    b[c] = s / a[c][c];
  }
  return true;
}

}  // namespace

void FingerContacts::solve_rt(std::span<Vec3> x, std::span<const Vec3> prev,
                              std::span<const double> w, int substep, int substeps,
                              double dt_s) noexcept {
  if (n_touched_ == 0) return;
  const double a0 = static_cast<double>(substep) / substeps,
               a1 = static_cast<double>(substep + 1) / substeps;
  for (int s = 0; s < n_shapes_; ++s) {
    if (!shape_near_[s]) continue;
    pose_before_[s] = substep == 0 ? shapes_[s].pose_at(a0) : pose_now_[s];
    pose_now_[s] = shapes_[s].pose_at(a1);
  }
  const double weight = 1.0 / substeps;
  for (int k = 0; k < n_touched_; ++k) {
    const Touched& t = touched_[k];
    if (!(w[t.node] > 0)) continue;
    solve_node_rt(t, x, prev, w, dt_s, weight);
  }
}

int FingerContacts::gather_rt(const Touched& t, Vec3 p, double dts, Contact* c, bool& any,
                              std::span<const Vec3> x, std::span<const Vec3> prev) const noexcept {
  int m = 0;
  any = false;
  const double inv_dts2 = 1.0 / (dts * dts);
  for (int e = 0; e < t.n_shapes; ++e) {
    const int si = t.shape[e];
    const WorldShape& s = shapes_[si];
    const Pose& pose = pose_now_[si];
    // Most candidates of a step are out of reach in a given substep (77 % in crease-bench
    // world's scenes): a lower bound on the patch's distance from the shape (the node's from the
    // core, less the shape's growth and the patch's reach) rules most of those out before the
    // patch's deepest point is sought (three core projections and a surface query).
    const Vec3 xl = pose.inverse_apply(p);
    if (patch_distance_bound(si, xl) >= half_thickness_ + kInactiveReachMm) continue;
    const Geometry geo = geometry(s, pose, t, to_local(pose, t, xl));
    if (geo.pen <= -kInactiveReachMm) continue;
    // Shapes of one rigid body (a fingertip's cover, pad and back) overlap: a node inside two
    // of them leaves through the nearer surface, never gets squeezed between them.
    int same = -1;
    for (int q = 0; q < m; ++q)
      if (shapes_[c[q].shape].side == s.side && shapes_[c[q].shape].body == s.body) same = q;
    if (same >= 0) {
      if (!better_exit(geo.pen, c[same].pen)) continue;
      --m;
      if (same != m) c[same] = c[m];
    }
    Contact& k = c[m++];
    k.n = geo.n;
    k.pen = geo.pen;
    // Compliance of the cover under this node: 1 / (N/mm) = mm/N = 1e-3 m/N (the sheet's unit).
    k.alpha = 1e-3 / (s.stiffness_n_per_mm3 * t.area_mm2) * inv_dts2;
    k.mu = cfg_.finger_friction ? s.friction : 0.0;
    k.point = geo.point;
    k.surface_move = geo.point - pose_before_[si].apply(pose.inverse_apply(geo.point));
    k.shape = si;
    any = any || geo.pen > 0;
  }
  if (m == 0) return 0;
  if (t.support >= 0) {  // a layer on the table under the node: it rests on that instead
    const Vec3 q = x[t.support];
    const double pen = q.z + 2.0 * half_thickness_ - p.z;
    if (pen > -kInactiveReachMm) {
      Contact& k = c[m++];
      k = Contact{};
      k.n = {0, 0, 1};
      k.pen = pen;
      k.mu = cfg_.layer_friction;
      k.surface_move = q - prev[t.support];
      k.shape = kSupport;
      any = any || pen > 0;
    }
    return m;
  }
  const double pen_table = half_thickness_ + cfg_.table_height_mm - p.z;
  if (pen_table > -kInactiveReachMm && over_extent(p, cfg_.table_extent_mm)) {
    Contact& k = c[m++];
    k = Contact{};
    k.n = {0, 0, 1};
    k.pen = pen_table;
    k.mu = table_mu();
    any = any || pen_table > 0;
  }
  return m;
}

Vec3 FingerContacts::normal_rt(Contact* c, int m, double w) noexcept {
  // The block's LCP, active set by hand (at most m + 1 rounds).
  bool active[kMaxNodeContacts];
  for (int e = 0; e < m; ++e) active[e] = c[e].pen > 0;
  double lambda[kMaxNodeContacts] = {};
  for (int round = 0; round <= m; ++round) {
    int idx[kMaxNodeContacts], na = 0;
    for (int e = 0; e < m; ++e)
      if (active[e]) idx[na++] = e;
    double a[kMaxNodeContacts][kMaxNodeContacts], b[kMaxNodeContacts];
    for (int r = 0; r < na; ++r) {
      for (int q = 0; q < na; ++q)
        a[r][q] = w * dot(c[idx[r]].n, c[idx[q]].n) + (r == q ? c[idx[r]].alpha : 0.0);
      b[r] = c[idx[r]].pen;
    }
    for (int e = 0; e < m; ++e) lambda[e] = 0;
    if (na > 0 && !solve_small(a, b, na)) break;
    int worst = -1;
    for (int r = 0; r < na; ++r) {
      lambda[idx[r]] = b[r];
      if (b[r] < 0 && (worst < 0 || b[r] < lambda[worst])) worst = idx[r];
    }
    if (worst >= 0) {
      active[worst] = false;
      continue;
    }
    // An inactive contact the solution pushes into joins the block.
    Vec3 move;
    for (int e = 0; e < m; ++e) move += (w * lambda[e]) * c[e].n;
    int join = -1;
    for (int e = 0; e < m && join < 0; ++e)
      if (!active[e] && c[e].pen - dot(c[e].n, move) > 1e-12) join = e;
    if (join < 0) break;
    active[join] = true;
  }
  Vec3 move;
  for (int e = 0; e < m; ++e) {
    c[e].lambda = std::max(0.0, lambda[e]);
    move += (w * c[e].lambda) * c[e].n;
  }
  return move;
}

Vec3 FingerContacts::friction_rt(const Contact* c, int m, double w, double dts, Vec3 u0,
                                 Vec3* fric_on_node) noexcept {
  // The prox problem of the header comment, in the tangent plane of the contact carrying the
  // most. Returns the node's tangential correction; fric_on_node: each contact's share (mN).
  for (int e = 0; e < m; ++e) fric_on_node[e] = Vec3{};
  int main = -1;
  double cap[kMaxNodeContacts];
  double total_cap = 0;
  for (int e = 0; e < m; ++e) {
    cap[e] = w * c[e].mu * c[e].lambda;
    total_cap += cap[e];
    if (c[e].lambda > 0 && (main < 0 || c[e].lambda > c[main].lambda)) main = e;
  }
  if (main < 0 || !(total_cap > 0)) return {};
  const Vec3 nm = c[main].n;
  auto tangent = [&](Vec3 v) { return v - dot(v, nm) * nm; };
  const Vec3 a = tangent(u0);
  Vec3 s[kMaxNodeContacts];
  for (int e = 0; e < m; ++e) s[e] = c[e].shape != kTable ? tangent(c[e].surface_move) : Vec3{};
  Vec3 u = a;
  int stick = -1;
  for (int e = 0; e < m && stick < 0; ++e) {
    if (!(cap[e] > 0)) continue;
    Vec3 g = a - s[e];
    double merged = 0;
    for (int j = 0; j < m; ++j) {
      if (!(cap[j] > 0)) continue;
      const Vec3 d = s[e] - s[j];
      const double len = norm(d);
      if (len < 1e-12)
        merged += cap[j];
      else
        g -= (cap[j] / len) * d;
    }
    if (dot(g, g) <= merged * merged) stick = e;
  }
  if (stick >= 0) {
    u = s[stick];
  } else {  // Weiszfeld iterations: every contact slides
    for (int it = 0; it < 30; ++it) {
      Vec3 num = a;
      double den = 1.0;
      for (int j = 0; j < m; ++j) {
        if (!(cap[j] > 0)) continue;
        const double r = std::max(norm(u - s[j]), 1e-9);
        num += (cap[j] / r) * s[j];
        den += cap[j] / r;
      }
      u = (1.0 / den) * num;
    }
  }
  // Each contact's share: sliders their full capacity towards their surface's move, the
  // sticking one the rest.
  const double to_force = 1.0 / (w * dts * dts);  // mm -> kg mm / s^2 = mN
  Vec3 others;
  for (int e = 0; e < m; ++e) {
    if (e == stick || !(cap[e] > 0)) continue;
    const Vec3 d = s[e] - u;
    const double len = norm(d);
    if (len > 1e-12) fric_on_node[e] = (cap[e] * to_force / len) * d;
    others += fric_on_node[e];
  }
  if (stick >= 0) fric_on_node[stick] = to_force * (u - a) - others;
  return u - a;
}

void FingerContacts::solve_node_rt(const Touched& t, std::span<Vec3> x, std::span<const Vec3> prev,
                                   std::span<const double> ws, double dts, double weight) noexcept {
  const double w = ws[t.node];
  Vec3& p = x[t.node];
  Contact c[kMaxNodeContacts];
  Vec3 fric[kMaxNodeContacts];
  int m = 0;
  // Twice: the friction moves the node along the surfaces, and the second normal solve presses
  // it where it ends up (under a tilted pad the first, before the friction put the node back
  // under the pad's material point, would count the sheet's pull as compression).
  for (int pass = 0; pass < 2; ++pass) {
    bool any = false;
    const int mm = gather_rt(t, p, dts, c, any, x, prev);
    if (!any) {
      if (pass == 0) {
        hold_kg_[t.node] = 0.0;
        return;
      }
      break;
    }
    m = mm;
    p += normal_rt(c, m, w);
    p += friction_rt(c, m, w, dts, p - prev[t.node], fric);
  }
  // Reactions on the shapes, averaged over the step: mN -> N.
  const double inv_dts2 = 1.0 / (dts * dts);
  double hold_mn = 0;  // the friction the node can take, mu F (mN)
  for (int e = 0; e < m; ++e) hold_mn += c[e].mu * c[e].lambda * inv_dts2;
  hold_kg_[t.node] = hold_mn / kHoldAccelMmS2;
  for (int e = 0; e < m; ++e) {
    if (c[e].shape == kSupport && c[e].lambda > 0)
      carry_support_rt(t, c[e], x, prev, ws[t.support], dts);
    if (c[e].shape < 0) continue;
    ShapeLoad& l = load_[c[e].shape];
    const Vec3 f = (-1e-3 * weight) * fric[e];
    l.friction_n += f;
    l.friction_moment_nmm += cross(c[e].point, f);
    l.normal_n += (-1e-3 * weight * c[e].lambda * inv_dts2) * c[e].n;
  }
}

void FingerContacts::carry_support_rt(const Touched& t, const Contact& support, std::span<Vec3> x,
                                      std::span<const Vec3> prev, double wb, double dts) noexcept {
  // The node under, loaded by what presses the node above onto it (the same force: lambda over
  // the substep squared), between the table and the layer above: its own friction problem
  // (friction_rt) with both, the table still and the layer above moving as it just did. Its
  // normal needs nothing here: the table holds it (the sheet's contacts push it out).
  const int b = t.support;
  if (!(wb > 0)) return;
  Contact c[2];
  c[0].n = c[1].n = {0, 0, 1};
  c[0].mu = table_mu();
  c[0].shape = kTable;
  c[1].mu = cfg_.layer_friction;
  c[1].surface_move = x[t.node] - prev[t.node];
  c[1].shape = kSupport;
  // lambda is position x mass (kg mm): the node above's correction over its inverse mass.
  c[0].lambda = c[1].lambda = support.lambda;
  Vec3 fric[2];
  x[b] += friction_rt(c, 2, wb, dts, x[b] - prev[b], fric);
}

}  // namespace crease::world
