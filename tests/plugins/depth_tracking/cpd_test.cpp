// Non-rigid CPD (plugins/depth_tracking/cpd.h) on synthetic sheets: a flat grid of nodes (the
// model's prediction, the warm start) registered onto a cloud sampled from a smoothly deformed
// sheet. Errors are scored against the deformation's truth at each node's sheet coordinates.
#include "plugins/depth_tracking/cpd.h"

#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/errors.h"
#include "rt/alloc_guard.h"
#include "tests/plugins/depth_tracking/dense_cpd_reference.h"

using crease::depth::CpdParams;
using crease::depth::CpdResult;
using crease::depth::NonRigidCpd;
using V3 = Eigen::Vector3d;

namespace {

// The truth: sheet coordinates (u, v) mm -> world mm. A lift of 10 mm and a bend of 25 mm
// amplitude, normal to the flat sheet: smooth on the scale of beta. (Point-to-point CPD barely
// sees motion along the surface: a grid slides by a few mm on its own cloud, see README.md; the
// tests score the normal error, which CPD recovers, and the whole error, stated separately.)
V3 deformed(double u, double v) {
  const double lu = 200.0, lv = 280.0;
  return {u, v, 10.0 + 25.0 * std::sin(std::numbers::pi * u / lu) * std::cos(0.5 * std::numbers::pi * v / lv)};
}

struct Grid {
  int cols, rows;
  double pitch;
  std::vector<V3> flat;   // the warm start
  std::vector<V3> truth;  // deformed(u, v) at each node
};

Grid make_grid(int cols, int rows, double pitch) {
  Grid g{cols, rows, pitch, {}, {}};
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double u = c * pitch, v = r * pitch;
      g.flat.emplace_back(u, v, 0.0);
      g.truth.push_back(deformed(u, v));
    }
  return g;
}

// A cloud sampled on the deformed sheet at random sheet coordinates, with depth-like noise.
std::vector<V3> sheet_cloud(const Grid& g, int n, double noise_mm, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uu(0.0, (g.cols - 1) * g.pitch), vv(0.0, (g.rows - 1) * g.pitch);
  std::normal_distribution<double> nz(0.0, noise_mm);
  std::vector<V3> x;
  for (int i = 0; i < n; ++i) x.push_back(deformed(uu(rng), vv(rng)) + V3(nz(rng), nz(rng), nz(rng)));
  return x;
}

double mean_error(const std::vector<V3>& a, const std::vector<V3>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]).norm();
  return s / static_cast<double>(a.size());
}

// The error along the flat sheet's normal (z), mm.
double normal_error(const std::vector<V3>& a, const std::vector<V3>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += std::abs(a[i].z() - b[i].z());
  return s / static_cast<double>(a.size());
}

CpdParams sheet_params() {
  CpdParams p;
  p.beta_mm = 40.0;
  p.lambda = 2.0;
  p.w = 0.1;
  p.max_iterations = 100;
  p.tolerance = 1e-6;
  return p;
}

}  // namespace

TEST_CASE("CPD recovers a smooth deformation of a grid from a flat warm start") {
  const Grid g = make_grid(15, 20, 14.0);  // 300 nodes, 196 x 266 mm
  const auto x = sheet_cloud(g, 3000, 0.5, 1);
  NonRigidCpd cpd;
  cpd.configure(sheet_params(), 600, 5000);
  std::vector<V3> y(g.flat.size());
  const CpdResult r = cpd.register_cloud(g.flat, x, y);
  REQUIRE(r.ok);
  CHECK(r.converged);
  const double before = normal_error(g.flat, g.truth);
  const double after = normal_error(y, g.truth);
  MESSAGE("mean normal error before " << before << " mm, after " << after << " mm (whole error "
          << mean_error(y, g.truth) << " mm), " << r.iterations << " iterations, sigma "
          << std::sqrt(r.sigma2_mm2) << " mm");
  CHECK(before > 20.0);  // the warm start alone is far off: the registration does the work
  CHECK(after < 1.5);
  CHECK(mean_error(y, g.truth) < 8.0);
}

TEST_CASE("CPD still converges with 30 % of the points removed and 10 % outliers") {
  const Grid g = make_grid(15, 20, 14.0);
  auto full = sheet_cloud(g, 3000, 0.5, 2);
  // Remove 30 %: a contiguous band of the sheet (a hole, as an occluding hand leaves) ...
  std::vector<V3> x;
  for (const V3& p : full)
    if (!(p.x() > 70.0 && p.x() < 70.0 + 0.3 * 196.0)) x.push_back(p);
  CHECK(x.size() < 0.75 * full.size());
  // ... and add outliers, 10 % of what is left, uniform in a box around the sheet.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> bx(-50.0, 250.0), by(-50.0, 320.0), bz(-40.0, 80.0);
  const std::size_t outliers = x.size() / 9;  // 10 % of the final cloud
  for (std::size_t i = 0; i < outliers; ++i) x.emplace_back(bx(rng), by(rng), bz(rng));

  NonRigidCpd cpd;
  CpdParams p = sheet_params();
  p.max_iterations = 400;  // the outliers slow the last digits of the objective down
  cpd.configure(p, 600, 5000);
  std::vector<V3> y(g.flat.size());
  std::vector<double> support(g.flat.size());
  const CpdResult r = cpd.register_cloud(g.flat, x, y, support);
  REQUIRE(r.ok);
  CHECK(r.converged);
  const double after = normal_error(y, g.truth);
  MESSAGE("with hole and outliers: mean normal error " << after << " mm (whole " << mean_error(y, g.truth)
          << " mm), " << r.iterations << " iterations");
  CHECK(after < 2.0);
  // Support: nodes inside the hole explain fewer points than nodes on the observed sheet.
  double in_hole = 0.0, outside = 0.0;
  int nh = 0, no = 0;
  for (std::size_t i = 0; i < g.flat.size(); ++i) {
    const double u = g.flat[i].x();
    if (u > 90.0 && u < 110.0) { in_hole += support[i]; ++nh; }
    if (u < 40.0 || u > 160.0) { outside += support[i]; ++no; }
  }
  CHECK(in_hole / nh < 0.25 * (outside / no));

  // The variant without the outlier term (w = 0) on the same cloud does worse: the outliers pull.
  CpdParams p0 = p;
  p0.w = 0.0;
  p0.max_iterations = 100;  // it does not converge; 100 iterations show it (and keep ASan quick)
  NonRigidCpd cpd0;
  cpd0.configure(p0, 600, 5000);
  std::vector<V3> y0(g.flat.size());
  REQUIRE(cpd0.register_cloud(g.flat, x, y0).ok);
  MESSAGE("same cloud, w = 0: " << normal_error(y0, g.truth) << " mm");
  CHECK(normal_error(y0, g.truth) > after);
}

TEST_CASE("CPD matches the dense textbook reference") {
  const Grid g = make_grid(8, 10, 25.0);  // 80 nodes
  auto x = sheet_cloud(g, 600, 0.5, 4);
  CpdParams p = sheet_params();
  p.max_iterations = 40;
  NonRigidCpd cpd;
  cpd.configure(p, 100, 1000);
  std::vector<V3> y(g.flat.size());
  std::vector<double> support(g.flat.size());
  const CpdResult r = cpd.register_cloud(g.flat, x, y, support);
  REQUIRE(r.ok);
  Eigen::MatrixXd xm(x.size(), 3), ym(g.flat.size(), 3);
  for (std::size_t i = 0; i < x.size(); ++i) xm.row(static_cast<Eigen::Index>(i)) = x[i].transpose();
  for (std::size_t i = 0; i < g.flat.size(); ++i) ym.row(static_cast<Eigen::Index>(i)) = g.flat[i].transpose();
  const auto d = crease::depth::test::dense_cpd(xm, ym, p);
  CHECK(d.iterations == r.iterations);
  double worst = 0.0, worst_p1 = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    worst = std::max(worst, (y[i] - d.y.row(static_cast<Eigen::Index>(i)).transpose()).norm());
    worst_p1 = std::max(worst_p1, std::abs(support[i] - d.p1[static_cast<Eigen::Index>(i)]));
  }
  MESSAGE("largest node difference to the dense reference: " << worst << " mm");
  CHECK(worst < 1e-4);  // 0.1 micrometre: the two solves differ only by rounding
  CHECK(worst_p1 < 1e-4);
}

TEST_CASE("identical inputs give identical outputs; a call allocates nothing") {
  const Grid g = make_grid(12, 12, 15.0);
  const auto x = sheet_cloud(g, 1500, 0.5, 5);
  NonRigidCpd cpd;
  cpd.configure(sheet_params(), 200, 2000);
  std::vector<V3> a(g.flat.size()), b(g.flat.size());
  std::vector<double> sa(g.flat.size()), sb(g.flat.size());
  REQUIRE(cpd.register_cloud(g.flat, x, a, sa).ok);
  REQUIRE(crease::rt::alloc_hooks_installed());
  const auto before = crease::rt::rt_allocation_count();
  CpdResult r;
  {
    crease::rt::ScopedRtMark mark;
    r = cpd.register_cloud(g.flat, x, b, sb);
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  REQUIRE(r.ok);
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i] == b[i]);  // bit for bit
    CHECK(sa[i] == sb[i]);
  }
}

TEST_CASE("a cloud larger than max_points is thinned and the dropped points counted") {
  const Grid g = make_grid(10, 10, 20.0);
  const auto x = sheet_cloud(g, 2500, 0.5, 6);
  NonRigidCpd cpd;
  cpd.configure(sheet_params(), 100, 1000);
  std::vector<V3> y(g.flat.size());
  const CpdResult r = cpd.register_cloud(g.flat, x, y);
  REQUIRE(r.ok);
  CHECK(r.points_used == 834);  // every third point
  CHECK(r.points_dropped == 2500 - 834);
  CHECK(normal_error(y, g.truth) < 2.0);
  // More nodes than configured: refused, nothing written.
  const Grid big = make_grid(11, 10, 20.0);
  std::vector<V3> yb(big.flat.size());
  CHECK_FALSE(cpd.register_cloud(big.flat, x, yb).ok);
}

TEST_CASE("beta, lambda or w out of range is a ConfigError naming the key") {
  NonRigidCpd cpd;
  const auto expect = [&](CpdParams p, const char* key) {
    try {
      cpd.configure(p, 10, 10);
      FAIL("no error for " << key);
    } catch (const crease::ConfigError& e) {
      CHECK(std::string(e.what()).find(key) != std::string::npos);
    }
  };
  CpdParams p;
  p.beta_mm = 0.0;
  expect(p, "beta_mm");
  p = {};
  p.lambda = -1.0;
  expect(p, "lambda");
  p = {};
  p.w = 1.0;
  expect(p, "w:");
  CHECK_NOTHROW(cpd.configure(CpdParams{}, 10, 10));
}
