// The link kernel (seed 001 Eqs. 2-3, one Gauss-Seidel pass): hand-computed single links,
// the padded batch layout, the AVX2 path against the lane-by-lane path, convergence.
#include "plugins/sheet_model/link_kernel.h"

#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace crease::sheet;

namespace {

// A 2-node sheet with one link 0-1 along u.
Topology one_link() {
  Topology t;
  t.grid = {2, 1, 1.0, 1.0, 1.0, 0.0};
  t.a = {0};
  t.b = {1};
  t.kind = {LinkKind::structural};
  return t;
}

double dist(Vec3 a, Vec3 b) { return norm(b - a); }

}  // namespace

TEST_CASE("a link moves its ends along it by their weights") {
  const Topology t = one_link();
  LinkKernel k;
  k.configure(t);
  k.set_link(0, 1.0, 0.25, 0.75);  // e.g. w_a = 1, w_b = 3, alpha = 0: w_a / (w_a + w_b)
  std::vector<Vec3> x = {{0, 0, 0}, {3, 0, 0}};  // stretched by 2
  k.project_rt(x);
  CHECK(x[0].x == doctest::Approx(0.5));  // moves w_a/(w_a+w_b) * 2
  CHECK(x[1].x == doctest::Approx(1.5));
  CHECK(x[1].x - x[0].x == doctest::Approx(1.0));
}

TEST_CASE("the weights follow the link's ends when the layout stores it reversed") {
  Topology t = one_link();
  t.a = {1};
  t.b = {0};  // stored b -> a: the kernel flips it
  LinkKernel k;
  k.configure(t);
  k.set_link(0, 1.0, 0.25, 0.75);  // 0.25 for node 1 (topo a), 0.75 for node 0
  std::vector<Vec3> x = {{0, 0, 0}, {3, 0, 0}};
  k.project_rt(x);
  CHECK(x[0].x == doctest::Approx(1.5));
  CHECK(x[1].x == doctest::Approx(2.5));
}

TEST_CASE("coincident ends are left alone (no division by zero)") {
  const Topology t = one_link();
  LinkKernel k;
  k.configure(t);
  k.set_link(0, 1.0, 0.5, 0.5);
  std::vector<Vec3> x = {{1, 2, 3}, {1, 2, 3}};
  k.project_rt(x);
  CHECK(x[0].x == 1.0);
  CHECK(x[1].x == 1.0);
  CHECK(x[1].z == 3.0);
}

TEST_CASE("nodes no link moves keep their exact double positions") {
  const Topology t = one_link();
  LinkKernel k;
  k.configure(t);
  k.set_link(0, 1.0, 0.0, 0.0);  // both ends pinned
  std::vector<Vec3> x = {{0.1234567890123, 0, 0}, {3.000000000001, 0, 0}};
  k.project_rt(x);
  CHECK(x[0].x == 0.1234567890123);
  CHECK(x[1].x == 3.000000000001);
}

namespace {

// One pass on the default sheet (stretched 5 % and perturbed) through the vector path and
// the lane-by-lane path (same order), then 200 passes: the strain must fall.
void check_default_sheet(int max_simd_width) {
  const Topology t = build_topology(GridParams{}, TopologyParams{});
  LinkKernel k;
  k.configure(t, max_simd_width);
  const int width = k.max_width();
  MESSAGE("batches=" << k.batch_count() << " lanes=" << k.lane_count() << " width=" << width);
  CHECK(k.lane_count() >= t.link_count());
  std::vector<double> rest(t.link_count());
  const Grid& g = t.grid;
  auto flat = [&g](int n) { return Vec3{(n % g.w) * g.du, (n / g.w) * g.dv, 0.0}; };
  for (int l = 0; l < t.link_count(); ++l) {
    rest[l] = dist(flat(t.a[l]), flat(t.b[l]));
    k.set_link(l, rest[l], 0.5, 0.5);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> x0(g.count());
  for (int n = 0; n < g.count(); ++n) x0[n] = 1.05 * flat(n) + Vec3{u(rng), u(rng), u(rng)};
  auto max_strain = [&](const std::vector<Vec3>& x) {
    double e = 0;
    for (int l = 0; l < t.link_count(); ++l) e = std::max(e, std::fabs(dist(x[t.a[l]], x[t.b[l]]) / rest[l] - 1.0));
    return e;
  };
  std::vector<Vec3> xv = x0, xs = x0;
  k.project_rt(xv);
  k.force_scalar(true);
  CHECK_FALSE(k.vectorized());
  k.project_rt(xs);
  double diff = 0, moved = 0;
  for (int n = 0; n < g.count(); ++n) {
    diff = std::max(diff, dist(xv[n], xs[n]));
    moved = std::max(moved, dist(x0[n], xs[n]));
  }
  CHECK(moved > 0.1);    // the pass did something
  // The same order; 1/|d| in float from sqrt vs rsqrt + Newton (AVX2) or rsqrt14 alone
  // (AVX-512, relative error <= 2^-14 per link move): an order mistake moves nodes by ~0.1 mm.
  CHECK(diff < (width == 16 ? 1e-2 : 1e-3));
  // Every link takes part: passes must shrink the worst strain.
  const double e0 = max_strain(x0);
  for (int it = 0; it < 200; ++it) k.project_rt(xs);
  CHECK(max_strain(xs) < 0.02 * e0);
}

}  // namespace

TEST_CASE("default sheet, widest blocks the CPU offers: vector and lane-by-lane paths agree, passes converge") {
  check_default_sheet(16);
}

TEST_CASE("default sheet, at most 8-lane (AVX2) blocks: vector and lane-by-lane paths agree, passes converge") {
  check_default_sheet(8);
}
