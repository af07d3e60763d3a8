#include "contacts.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace crease::sheet {
namespace {

constexpr int kMaxContactsPerNode = 4;
constexpr double kBaryTolerance = 0.05;  // accept projections slightly outside a triangle

// Barycentric coordinates of p's projection onto the plane of (a, b, c).
bool barycentric(Vec3 p, Vec3 a, Vec3 b, Vec3 c, double out[3]) {
  const Vec3 e0 = b - a, e1 = c - a, ep = p - a;
  const double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1);
  const double d20 = dot(ep, e0), d21 = dot(ep, e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 1e-12)) return false;
  const double v = (d11 * d20 - d01 * d21) / den;
  const double w = (d00 * d21 - d01 * d20) / den;
  out[0] = 1.0 - v - w;
  out[1] = v;
  out[2] = w;
  return out[0] >= -kBaryTolerance && out[1] >= -kBaryTolerance && out[2] >= -kBaryTolerance;
}

}  // namespace

void ContactSolver::configure(const Topology& topo, const GridParams& grid, const SolverParams& solver) {
  topo_ = &topo;
  thickness_ = grid.thickness_mm;
  half_thickness_ = 0.5 * grid.thickness_mm;
  friction_ = solver.friction;
  self_enabled_ = solver.self_collision;
  const int n = topo.grid.count();
  shape_pairs_.resize(static_cast<std::size_t>(n) * kMaxContactsPerNode);
  self_pairs_.resize(static_cast<std::size_t>(n) * 8);
  std::uint32_t buckets = 1;
  while (buckets < 2u * static_cast<std::uint32_t>(n)) buckets <<= 1;
  bucket_mask_ = buckets - 1;
  bucket_start_.assign(buckets + 1, 0);
  bucket_items_.assign(n, 0);
  node_cell_.assign(n, 0);
  node_ijk_.assign(static_cast<std::size_t>(n) * 3, 0);
  cell_mm_ = std::hypot(topo.grid.du, topo.grid.dv) + 2.0 * thickness_;
}

std::uint32_t ContactSolver::cell_hash(int cx, int cy, int cz) const noexcept {
  const std::uint32_t h = static_cast<std::uint32_t>(cx) * 73856093u ^
                          static_cast<std::uint32_t>(cy) * 19349663u ^
                          static_cast<std::uint32_t>(cz) * 83492791u;
  return h & bucket_mask_;
}

void ContactSolver::detect_rt(std::span<const Vec3> x, const CollisionWorld* world, double margin_mm) noexcept {
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
  stats_.shape_contacts = n_shape_;
  n_self_ = 0;
  if (self_enabled_) detect_self_rt(x, margin_mm);
  stats_.self_pairs = n_self_;
}

void ContactSolver::detect_self_rt(std::span<const Vec3> x, double margin_mm) noexcept {
  const int n = static_cast<int>(x.size());
  const double inv_cell = 1.0 / cell_mm_;
  auto cell_of = [inv_cell](double c) { return static_cast<int>(std::floor(c * inv_cell)); };
  // Counting sort of nodes into hash buckets.
  std::fill(bucket_start_.begin(), bucket_start_.end(), 0u);
  for (int i = 0; i < n; ++i) {
    std::int32_t* c = &node_ijk_[3 * static_cast<std::size_t>(i)];
    c[0] = cell_of(x[i].x);
    c[1] = cell_of(x[i].y);
    c[2] = cell_of(x[i].z);
    node_cell_[i] = cell_hash(c[0], c[1], c[2]);
    ++bucket_start_[node_cell_[i] + 1];
  }
  for (std::size_t b = 1; b < bucket_start_.size(); ++b) bucket_start_[b] += bucket_start_[b - 1];
  // bucket_start_[b] is now the start of bucket b; fill using a moving cursor in bucket_start_[b+1]-..
  for (int i = 0; i < n; ++i) bucket_items_[bucket_start_[node_cell_[i]]++] = i;
  // Shift back: after filling, bucket_start_[b] is the end of bucket b == start of b+1.
  for (std::size_t b = bucket_start_.size() - 1; b > 0; --b) bucket_start_[b] = bucket_start_[b - 1];
  bucket_start_[0] = 0;

  const double reach = thickness_ + margin_mm;
  const auto& tri = topo_->tri;
  const int nt = topo_->triangle_count();
  const int gw = topo_->grid.w;
  for (int t = 0; t < nt; ++t) {
    const int ia = tri[3 * t], ib = tri[3 * t + 1], ic = tri[3 * t + 2];
    const int ti = ia % gw, tj = ia / gw;  // the triangle's first corner in the grid
    const Vec3 a = x[ia], b = x[ib], c = x[ic];
    const Vec3 nrm = normalized(cross(b - a, c - a));
    const int x0 = cell_of(std::min({a.x, b.x, c.x}) - reach), x1 = cell_of(std::max({a.x, b.x, c.x}) + reach);
    const int y0 = cell_of(std::min({a.y, b.y, c.y}) - reach), y1 = cell_of(std::max({a.y, b.y, c.y}) + reach);
    const int z0 = cell_of(std::min({a.z, b.z, c.z}) - reach), z1 = cell_of(std::max({a.z, b.z, c.z}) + reach);
    if ((x1 - x0) > 3 || (y1 - y0) > 3 || (z1 - z0) > 3) continue;  // torn / degenerate triangle
    for (int cx = x0; cx <= x1; ++cx) {
      for (int cy = y0; cy <= y1; ++cy) {
        for (int cz = z0; cz <= z1; ++cz) {
          const std::uint32_t h = cell_hash(cx, cy, cz);
          for (std::uint32_t s = bucket_start_[h]; s < bucket_start_[h + 1]; ++s) {
            const int p = bucket_items_[s];
            // Each node sits in one cell: visit it only from that cell (no duplicates).
            const std::int32_t* pc = &node_ijk_[3 * static_cast<std::size_t>(p)];
            if (pc[0] != cx || pc[1] != cy || pc[2] != cz) continue;
            if (std::abs(p % gw - ti) <= kSelfSkipCells + 1 && std::abs(p / gw - tj) <= kSelfSkipCells + 1)
              continue;  // same layer, near in the sheet (incident nodes included)
            const double d = dot(x[p] - a, nrm);
            if (std::fabs(d) >= reach) continue;
            double bary[3];
            if (!barycentric(x[p], a, b, c, bary)) continue;
            if (n_self_ >= static_cast<int>(self_pairs_.size())) {
              ++stats_.dropped;
              continue;
            }
            self_pairs_[n_self_++] = {p, t, d >= 0 ? 1.0 : -1.0};
          }
        }
      }
    }
  }
}

void ContactSolver::solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w) noexcept {
  // Nodes against rigid shapes: push out to half the thickness, then Coulomb friction on
  // the substep's tangential displacement.
  for (int k = 0; k < n_shape_; ++k) {
    const ShapePair& c = shape_pairs_[k];
    if (w[c.node] <= 0) continue;
    Vec3& p = x[c.node];
    const double pen = c.offset + half_thickness_ - dot(c.normal, p);
    if (pen <= 0) continue;
    p += pen * c.normal;
    Vec3 dt = p - prev[c.node];
    dt -= dot(dt, c.normal) * c.normal;
    const double slide = norm(dt);
    if (slide <= friction_ * pen) {
      p -= dt;
    } else if (slide > 0) {
      p -= (friction_ * pen / slide) * dt;
    }
  }
  // Nodes against triangles of other layers: keep the frame's side, thickness apart.
  const auto& tri = topo_->tri;
  for (int k = 0; k < n_self_; ++k) {
    const SelfPair& c = self_pairs_[k];
    const int ia = tri[3 * c.tri], ib = tri[3 * c.tri + 1], ic = tri[3 * c.tri + 2];
    const Vec3 a = x[ia], b = x[ib], cc = x[ic];
    const Vec3 nrm = normalized(cross(b - a, cc - a));
    double bary[3];
    if (!barycentric(x[c.node], a, b, cc, bary)) continue;
    const Vec3 q = bary[0] * a + bary[1] * b + bary[2] * cc;
    const double d = c.side * dot(x[c.node] - q, nrm);
    if (d >= thickness_) continue;
    const double wsum = w[c.node] + bary[0] * bary[0] * w[ia] + bary[1] * bary[1] * w[ib] +
                        bary[2] * bary[2] * w[ic];
    if (wsum <= 0) continue;
    const Vec3 dir = c.side * nrm;
    const double s = (thickness_ - d) / wsum;
    x[c.node] += (s * w[c.node]) * dir;
    x[ia] -= (s * bary[0] * w[ia]) * dir;
    x[ib] -= (s * bary[1] * w[ib]) * dir;
    x[ic] -= (s * bary[2] * w[ic]) * dir;
  }
}

}  // namespace crease::sheet
