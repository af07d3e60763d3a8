#include "contacts.h"

#include <algorithm>
#include <cmath>
#include <bit>
#include <cstdlib>
#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace crease::sheet {
namespace {

constexpr int kMaxContactsPerNode = 4;
constexpr double kBaryTolerance = 0.05;  // accept projections slightly outside a triangle

bool barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n, double nn,
                 double out[3]) {
  return barycentric_inside(p, a, b, c, n, nn, kBaryTolerance, out);
}

constexpr double kMinArea2 = 1e-12;  // mm^4: |n|^2 of a degenerate triangle

// Node screening for one pair of triangles: a float box, and the grid box of nodes that are
// sheet neighbours of both. Arrays are padded to whole blocks of kScreenBlock nodes.
constexpr int kScreenBlock = 32;
struct Screen {
  float lo[3], hi[3];
  std::int32_t ni0, ni1, nj0, nj1;
};
struct ScreenNodes {
  const float *x, *y, *z;
  const std::int32_t *gi, *gj;
};

// Bit e: node base + e is inside the box and not in the neighbour box.
std::uint32_t screen_scalar(const Screen& sc, const ScreenNodes& nd, int base) noexcept {
  std::uint32_t mask = 0;
  for (int e = 0; e < kScreenBlock; ++e) {
    const int p = base + e;
    const bool inside = nd.x[p] >= sc.lo[0] && nd.x[p] <= sc.hi[0] && nd.y[p] >= sc.lo[1] && nd.y[p] <= sc.hi[1] &&
                        nd.z[p] >= sc.lo[2] && nd.z[p] <= sc.hi[2];
    const bool near = nd.gi[p] >= sc.ni0 && nd.gi[p] <= sc.ni1 && nd.gj[p] >= sc.nj0 && nd.gj[p] <= sc.nj1;
    if (inside && !near) mask |= std::uint32_t{1} << e;
  }
  return mask;
}

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx2"))) std::uint32_t screen_avx2(const Screen& sc, const ScreenNodes& nd, int base) noexcept {
  std::uint32_t mask = 0;
  for (int h = 0; h < kScreenBlock; h += 8) {
    const int p = base + h;
    const __m256 px = _mm256_loadu_ps(nd.x + p), py = _mm256_loadu_ps(nd.y + p), pz = _mm256_loadu_ps(nd.z + p);
    __m256 in = _mm256_and_ps(_mm256_cmp_ps(px, _mm256_set1_ps(sc.lo[0]), _CMP_GE_OQ),
                              _mm256_cmp_ps(px, _mm256_set1_ps(sc.hi[0]), _CMP_LE_OQ));
    in = _mm256_and_ps(in, _mm256_cmp_ps(py, _mm256_set1_ps(sc.lo[1]), _CMP_GE_OQ));
    in = _mm256_and_ps(in, _mm256_cmp_ps(py, _mm256_set1_ps(sc.hi[1]), _CMP_LE_OQ));
    in = _mm256_and_ps(in, _mm256_cmp_ps(pz, _mm256_set1_ps(sc.lo[2]), _CMP_GE_OQ));
    in = _mm256_and_ps(in, _mm256_cmp_ps(pz, _mm256_set1_ps(sc.hi[2]), _CMP_LE_OQ));
    const auto inside = static_cast<std::uint32_t>(_mm256_movemask_ps(in));
    if (inside == 0) continue;
    const __m256i gi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(nd.gi + p));
    const __m256i gj = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(nd.gj + p));
    // near: ni0 <= gi <= ni1 and nj0 <= gj <= nj1, as ni0 - 1 < gi < ni1 + 1 and likewise
    __m256i nr = _mm256_and_si256(_mm256_cmpgt_epi32(gi, _mm256_set1_epi32(sc.ni0 - 1)),
                                  _mm256_cmpgt_epi32(_mm256_set1_epi32(sc.ni1 + 1), gi));
    nr = _mm256_and_si256(nr, _mm256_cmpgt_epi32(gj, _mm256_set1_epi32(sc.nj0 - 1)));
    nr = _mm256_and_si256(nr, _mm256_cmpgt_epi32(_mm256_set1_epi32(sc.nj1 + 1), gj));
    const auto near = static_cast<std::uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(nr)));
    mask |= (inside & ~near & 0xFFu) << h;
  }
  return mask;
}
#else
std::uint32_t screen_avx2(const Screen& sc, const ScreenNodes& nd, int base) noexcept { return screen_scalar(sc, nd, base); }
#endif

}  // namespace

void ContactSolver::configure(const Topology& topo, const GridParams& grid, const SolverParams& solver) {
  topo_ = &topo;
  thickness_ = grid.thickness_mm;
  half_thickness_ = 0.5 * grid.thickness_mm;
  friction_ = solver.friction;
  layer_friction_ = solver.layer_friction;
  self_enabled_ = solver.self_collision;
  const int n = topo.grid.count();
  shape_pairs_.resize(static_cast<std::size_t>(n) * kMaxContactsPerNode);
  self_pairs_.resize(static_cast<std::size_t>(n) * 16);
  shape_active_.reserve(static_cast<int>(shape_pairs_.size()));
  self_active_.resize(self_pairs_.size());
  cand_tris_.assign(static_cast<std::size_t>(topo.triangle_count()), 0);
  tri_stamp_.assign(static_cast<std::size_t>(topo.triangle_count()), 0);
  tri_n_.assign(static_cast<std::size_t>(topo.triangle_count()), Vec3{});
  node_gi_.resize(n);
  node_gj_.resize(n);
  for (int i = 0; i < n; ++i) {
    node_gi_[i] = i % topo.grid.w;
    node_gj_[i] = i / topo.grid.w;
  }
  // Screening arrays padded to whole blocks; padding nodes never pass (NaN positions).
  const std::size_t padded = static_cast<std::size_t>((n + kScreenBlock - 1) / kScreenBlock * kScreenBlock);
  fx_.assign(padded, std::numeric_limits<float>::quiet_NaN());
  fy_.assign(padded, std::numeric_limits<float>::quiet_NaN());
  fz_.assign(padded, std::numeric_limits<float>::quiet_NaN());
  block_box_.assign(padded / kScreenBlock * 6, 0.0f);
  gi_.assign(padded, 0);
  gj_.assign(padded, 0);
  for (int i = 0; i < n; ++i) {
    gi_[i] = node_gi_[i];
    gj_[i] = node_gj_[i];
  }
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
  has_simd_ = __builtin_cpu_supports("avx2");
#endif
  use_simd_ = has_simd_;
  has_select_simd_ = layer_select_simd_available();
  use_select_simd_ = has_select_simd_;
  cell_mm_ = std::hypot(topo.grid.du, topo.grid.dv) + 2.0 * thickness_;
}

void ContactSolver::detect_rt(std::span<const Vec3> x, const CollisionWorld* world, double margin_mm,
                              double lateral_mm) noexcept {
  n_shape_ = 0;
  const int n = static_cast<int>(x.size());
  if (world != nullptr && world->shape_count() > 0) {
    ShapeContact c[kMaxContactsPerNode];
    for (int i = 0; i < n; ++i) {
      const int k = world->query_rt(x[i], half_thickness_ + margin_mm, c, kMaxContactsPerNode);
      for (int e = 0; e < k; ++e) {
        if (n_shape_ >= static_cast<int>(shape_pairs_.size())) {
          ++stats_.dropped;
          break;
        }
        shape_pairs_[n_shape_++] = {i, c[e].normal, c[e].offset_mm};
      }
    }
  }
  n_self_ = 0;
  if (self_enabled_) detect_self_rt(x, margin_mm, std::max(0.0, lateral_mm));
  shape_active_.clear();
  for (int k = 0; k < n_shape_; ++k) {
    const ShapePair& c = shape_pairs_[k];
    shape_active_.push(c.node, c.normal, c.offset);
  }
  std::copy_n(self_pairs_.begin(), n_self_, self_active_.begin());
  n_self_active_ = n_self_;
  ++stamp_;
  if (stamp_ == 0) {  // wrapped: no triangle may look current
    std::fill(tri_stamp_.begin(), tri_stamp_.end(), 0u);
    stamp_ = 1;
  }
  n_cand_tris_ = 0;
  for (int k = 0; k < n_self_; ++k) {
    const std::int32_t t = self_pairs_[k].tri;
    if (tri_stamp_[t] == stamp_) continue;
    tri_stamp_[t] = stamp_;
    cand_tris_[n_cand_tris_++] = t;
  }
  stats_.shape_contacts = shape_active_.size();
  stats_.self_pairs = n_self_active_;
  stats_.self_candidates = n_self_;
}

void ContactSolver::select_rt(std::span<const Vec3> x, double margin_mm) noexcept {
  const double rs = half_thickness_ + margin_mm;
  shape_active_.clear();
  for (int k = 0; k < n_shape_; ++k) {
    const ShapePair& c = shape_pairs_[k];
    if (dot(c.normal, x[c.node]) - c.offset < rs) shape_active_.push(c.node, c.normal, c.offset);
  }
  const double reach = thickness_ + margin_mm;
  const auto& tri = topo_->tri;
  for (int k = 0; k < n_cand_tris_; ++k) {  // each candidate triangle's normal once
    const std::int32_t t = cand_tris_[k];
    const Vec3 a = x[tri[3 * t]];
    tri_n_[t] = cross(x[tri[3 * t + 1]] - a, x[tri[3 * t + 2]] - a);
  }
  n_self_active_ = layer_select(self_pairs_.data(), n_self_, tri.data(), x.data(), tri_n_.data(), reach,
                                kBaryTolerance, kMinArea2, self_active_.data(), use_select_simd_);
  stats_.shape_contacts = shape_active_.size();
  stats_.self_pairs = n_self_active_;
}

void ContactSolver::detect_self_rt(std::span<const Vec3> x, double margin_mm, double lateral_mm) noexcept {
  const int n = static_cast<int>(x.size());
  const double inv_cell = 1.0 / cell_mm_;
  auto cell_of = [inv_cell](double c) {  // floor without a libm call, clamped (NaN too) to +-1e9
    double s = c * inv_cell;
    if (!(s > -1e9)) s = -1e9;
    if (!(s < 1e9)) s = 1e9;
    const int i = static_cast<int>(s);
    return i - (s < static_cast<double>(i) ? 1 : 0);
  };
  // Float copies for screening, and each block's box (blocks far from a triangle are skipped).
  const int blocks = (n + kScreenBlock - 1) / kScreenBlock;
  for (int k = 0; k < blocks; ++k) {
    float* bb = &block_box_[6 * static_cast<std::size_t>(k)];
    bb[0] = bb[1] = bb[2] = std::numeric_limits<float>::max();
    bb[3] = bb[4] = bb[5] = std::numeric_limits<float>::lowest();
    for (int i = k * kScreenBlock; i < std::min(n, (k + 1) * kScreenBlock); ++i) {
      fx_[i] = static_cast<float>(x[i].x);
      fy_[i] = static_cast<float>(x[i].y);
      fz_[i] = static_cast<float>(x[i].z);
      bb[0] = std::min(bb[0], fx_[i]);
      bb[1] = std::min(bb[1], fy_[i]);
      bb[2] = std::min(bb[2], fz_[i]);
      bb[3] = std::max(bb[3], fx_[i]);
      bb[4] = std::max(bb[4], fy_[i]);
      bb[5] = std::max(bb[5], fz_[i]);
    }
  }
  const double reach = thickness_ + margin_mm;
  const auto& tri = topo_->tri;
  const int nt = topo_->triangle_count();
  // The two triangles of a grid cell are consecutive: the nodes are screened once per pair
  // (set up lazily: most pairs have no candidate), each candidate tested against both.
  struct Tri {
    int t, ti, tj;  // index; the grid column / row of its first corner
    Vec3 a, b, c, n, nrm;
    double nn;
    double bl[3], bh[3];  // its box grown by reach, lateral and the barycentric tolerance
    double tol[3];        // accepted barycentric coordinates >= -tol
  };
  constexpr int r = kSelfSkipCells + 1;
  const ScreenNodes nd{fx_.data(), fy_.data(), fz_.data(), gi_.data(), gj_.data()};
  for (int t0 = 0; t0 < nt; t0 += 2) {
    const int t1 = std::min(t0 + 2, nt);
    // Screen with a box holding both triangles' grown boxes (the pair's extent is at least
    // each one's), grown a little more for float rounding, and the grid box of nodes that
    // are sheet neighbours of both.
    double mn[3] = {1e300, 1e300, 1e300}, mx[3] = {-1e300, -1e300, -1e300};
    Screen sc{{0, 0, 0}, {0, 0, 0}, -(1 << 30), 1 << 30, -(1 << 30), 1 << 30};
    for (int t = t0; t < t1; ++t) {
      for (int v = 0; v < 3; ++v) {
        const Vec3& p = x[tri[3 * t + v]];
        mn[0] = std::min(mn[0], p.x);
        mn[1] = std::min(mn[1], p.y);
        mn[2] = std::min(mn[2], p.z);
        mx[0] = std::max(mx[0], p.x);
        mx[1] = std::max(mx[1], p.y);
        mx[2] = std::max(mx[2], p.z);
      }
      const int first = tri[3 * t];
      sc.ni0 = std::max(sc.ni0, node_gi_[first] - r);
      sc.ni1 = std::min(sc.ni1, node_gi_[first] + r);
      sc.nj0 = std::max(sc.nj0, node_gj_[first] - r);
      sc.nj1 = std::min(sc.nj1, node_gj_[first] + r);
    }
    for (int e = 0; e < 3; ++e) {
      const double grow = reach + lateral_mm + 2.0 * kBaryTolerance * (mx[e] - mn[e]) + 1e-9;
      const double lo = mn[e] - grow, hi = mx[e] + grow;
      sc.lo[e] = static_cast<float>(lo - 1e-3 * (1.0 + std::fabs(lo)));
      sc.hi[e] = static_cast<float>(hi + 1e-3 * (1.0 + std::fabs(hi)));
    }
    Tri g[2];
    int ng = -1;  // set up on the first candidate
    for (int base = 0; base < n; base += kScreenBlock) {
      const float* bb = &block_box_[6 * static_cast<std::size_t>(base / kScreenBlock)];
      if (bb[3] < sc.lo[0] || bb[0] > sc.hi[0] || bb[4] < sc.lo[1] || bb[1] > sc.hi[1] || bb[5] < sc.lo[2] ||
          bb[2] > sc.hi[2])
        continue;
      std::uint32_t mask = use_simd_ ? screen_avx2(sc, nd, base) : screen_scalar(sc, nd, base);
      if (mask != 0 && ng < 0) {
        ng = 0;
        for (int t = t0; t < t1; ++t) {
          Tri& q = g[ng];
          const int ia = tri[3 * t], ib = tri[3 * t + 1], ic = tri[3 * t + 2];
          q.t = t;
          q.ti = node_gi_[ia];
          q.tj = node_gj_[ia];
          q.a = x[ia];
          q.b = x[ib];
          q.c = x[ic];
          q.n = cross(q.b - q.a, q.c - q.a);
          q.nn = dot(q.n, q.n);
          if (!(q.nn > kMinArea2)) continue;  // degenerate: no projection
          const double inv_len = 1.0 / std::sqrt(q.nn);
          q.nrm = inv_len * q.n;
          // A projection dist outside the edge opposite corner e has bary[e] = -dist |edge| / |n|.
          q.tol[0] = kBaryTolerance + lateral_mm * norm(q.c - q.b) * inv_len;
          q.tol[1] = kBaryTolerance + lateral_mm * norm(q.a - q.c) * inv_len;
          q.tol[2] = kBaryTolerance + lateral_mm * norm(q.b - q.a) * inv_len;
          const double tmn[3] = {std::min({q.a.x, q.b.x, q.c.x}), std::min({q.a.y, q.b.y, q.c.y}),
                                 std::min({q.a.z, q.b.z, q.c.z})};
          const double tmx[3] = {std::max({q.a.x, q.b.x, q.c.x}), std::max({q.a.y, q.b.y, q.c.y}),
                                 std::max({q.a.z, q.b.z, q.c.z})};
          bool torn = false;
          for (int e = 0; e < 3; ++e) {
            torn = torn || cell_of(tmx[e] + reach) - cell_of(tmn[e] - reach) > 3;
            // A projection accepted by barycentric() lies within 2 kBaryTolerance of the
            // extent outside the box: nodes outside bl..bh cannot pass both tests below.
            const double grow = reach + lateral_mm + 2.0 * kBaryTolerance * (tmx[e] - tmn[e]) + 1e-9;
            q.bl[e] = tmn[e] - grow;
            q.bh[e] = tmx[e] + grow;
          }
          if (!torn) ++ng;  // torn / degenerate triangle: skipped
        }
      }
      while (mask != 0) {
        const int p = base + std::countr_zero(mask);
        mask &= mask - 1;
        if (p >= n) break;
        const Vec3& xp = x[p];  // a reference: see solve_rt
        for (int k = 0; k < ng; ++k) {
          const Tri& q = g[k];
          if (std::abs(node_gi_[p] - q.ti) <= r && std::abs(node_gj_[p] - q.tj) <= r)
            continue;  // same layer, near in the sheet (incident nodes included)
          if (xp.x < q.bl[0] || xp.x > q.bh[0] || xp.y < q.bl[1] || xp.y > q.bh[1] || xp.z < q.bl[2] ||
              xp.z > q.bh[2])
            continue;
          const double d = dot(xp - q.a, q.nrm);
          if (std::fabs(d) >= reach) continue;
          double bary[3];
          if (!barycentric(xp, q.a, q.b, q.c, q.n, q.nn, bary) &&
              !(bary[0] >= -q.tol[0] && bary[1] >= -q.tol[1] && bary[2] >= -q.tol[2]))
            continue;
          if (n_self_ >= static_cast<int>(self_pairs_.size())) {
            ++stats_.dropped;
            continue;
          }
          self_pairs_[n_self_++] = {p, q.t, d >= 0 ? 1.0 : -1.0};
        }
      }
    }
  }
}

void ContactSolver::solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w,
                             bool with_self) noexcept {
  // Nodes against rigid shapes: push out to half the thickness, then Coulomb friction.
  shape_active_.solve_rt(x, prev, w, half_thickness_, friction_);
  if (!with_self) return;
  // Nodes against triangles of other layers: keep the frame's side, thickness apart.
  const auto& tri = topo_->tri;
  for (int k = 0; k < n_self_active_; ++k) {
    const SelfPair& c = self_active_[k];
    const int ia = tri[3 * c.tri], ib = tri[3 * c.tri + 1], ic = tri[3 * c.tri + 2];
    // References, not copies: GCC copies a Vec3 through the stack with a 16 + 8 byte store
    // and reads it back with loads that straddle both (a failed store forward, ~3 per pair).
    const Vec3 &a = x[ia], &b = x[ib], &cc = x[ic];
    const Vec3 n = cross(b - a, cc - a);
    const double nn = dot(n, n);
    if (!(nn > kMinArea2)) continue;
    // d = side * dot(x - q, n / |n|) with q the projection (so dot(x - a, n) / |n|);
    // most pairs are apart: test d >= thickness without a square root first.
    const double sd = c.side * dot(x[c.node] - a, n);
    if (sd >= 0 && sd * sd >= thickness_ * thickness_ * nn) continue;
    double bary[3];
    if (!barycentric(x[c.node], a, b, cc, n, nn, bary)) continue;
    const double inv_len = 1.0 / std::sqrt(nn);
    const double d = sd * inv_len;
    const Vec3 nrm = inv_len * n;
    const double wsum = w[c.node] + bary[0] * bary[0] * w[ia] + bary[1] * bary[1] * w[ib] +
                        bary[2] * bary[2] * w[ic];
    if (wsum <= 0) continue;
    const Vec3 dir = c.side * nrm;
    const double depth = thickness_ - d;
    const double s = depth / wsum;
    x[c.node] += (s * w[c.node]) * dir;
    x[ia] -= (s * bary[0] * w[ia]) * dir;
    x[ib] -= (s * bary[1] * w[ib]) * dir;
    x[ic] -= (s * bary[2] * w[ic]) * dir;
    if (layer_friction_ <= 0) continue;
    // Coulomb friction between the layers: the node's slip over the triangle's point under it
    // this substep, tangential part, cancelled whole while under layer_friction x depth
    // (sticking), else by that much (sliding); shared by the inverse masses like the push.
    const Vec3 slip =
        (x[c.node] - prev[c.node]) - (bary[0] * (x[ia] - prev[ia]) + bary[1] * (x[ib] - prev[ib]) +
                                      bary[2] * (x[ic] - prev[ic]));
    const Vec3 t = slip - dot(slip, dir) * dir;
    const double tl = std::sqrt(dot(t, t));
    if (!(tl > 0)) continue;
    const double bound = layer_friction_ * depth;
    const Vec3 corr = (tl <= bound ? 1.0 : bound / tl) / wsum * t;
    x[c.node] -= w[c.node] * corr;
    x[ia] += (bary[0] * w[ia]) * corr;
    x[ib] += (bary[1] * w[ib]) * corr;
    x[ic] += (bary[2] * w[ic]) * corr;
  }
}

}  // namespace crease::sheet
