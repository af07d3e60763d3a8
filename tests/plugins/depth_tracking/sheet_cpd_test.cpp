// The sheet-kernel CPD (plugins/depth_tracking/sheet_cpd.h): on a flat grid (where the sheet
// coordinates and the warm start's world positions give the same kernel) it is the textbook
// solver (cpd.h) at full rank; at the low rank it keeps it recovers the same bend; inactive
// nodes take no points and get no support; no allocation per call; identical inputs, identical
// outputs.
#include "plugins/depth_tracking/sheet_cpd.h"

#include <doctest/doctest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <random>
#include <vector>

#include "rt/alloc_guard.h"

using crease::depth::CpdParams;
using crease::depth::NonRigidCpd;
using crease::depth::SheetCpd;
using V3 = Eigen::Vector3d;

// Eigen's own heap (aligned_malloc) is plain malloc, which the operator-new hooks do not see:
// this executable's malloc counts the calls while `g_count_malloc` is set (glibc: __libc_malloc).
// Not under the sanitizers, whose runtimes own malloc.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define CREASE_COUNT_MALLOC 0
#else
#define CREASE_COUNT_MALLOC 1
#endif
namespace {
std::atomic<bool> g_count_malloc{false};
std::atomic<int> g_mallocs{0};
void* volatile g_sink = nullptr;
}  // namespace
#if CREASE_COUNT_MALLOC
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* malloc(std::size_t n) {
  if (g_count_malloc.load(std::memory_order_relaxed)) g_mallocs.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
#endif

namespace {

V3 deformed(double u, double v) {  // as cpd_test.cpp: lifted 10 mm, bent 25 mm
  return {u, v, 10.0 + 25.0 * std::sin(std::numbers::pi * u / 200.0) * std::cos(0.5 * std::numbers::pi * v / 280.0)};
}

struct Grid {
  std::vector<Eigen::Vector2d> uv;
  std::vector<V3> flat, truth;
};

Grid grid(int cols, int rows, double pitch) {
  Grid g;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      g.uv.emplace_back(c * pitch, r * pitch);
      g.flat.emplace_back(c * pitch, r * pitch, 0.0);  // world = (u, v, 0): the same kernel
      g.truth.push_back(deformed(c * pitch, r * pitch));
    }
  return g;
}

std::vector<V3> cloud(double umax, double vmax, int n, unsigned seed, double vmin = 0.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uu(0.0, umax), vv(vmin, vmax);
  std::normal_distribution<double> nz(0.0, 0.5);
  std::vector<V3> x;
  for (int i = 0; i < n; ++i) x.push_back(deformed(uu(rng), vv(rng)) + V3(nz(rng), nz(rng), nz(rng)));
  return x;
}

CpdParams params() {
  CpdParams p;
  p.max_iterations = 60;
  return p;
}

double normal_error(const std::vector<V3>& a, const std::vector<V3>& b, const std::vector<std::uint8_t>* only = nullptr) {
  double s = 0;
  int n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (only && !(*only)[i]) continue;
    s += std::abs(a[i].z() - b[i].z());
    ++n;
  }
  return s / n;
}

}  // namespace

TEST_CASE("full rank, every node active: the textbook solver's nodes") {
  const Grid g = grid(10, 8, 14.0);
  const auto x = cloud(9 * 14.0, 7 * 14.0, 600, 3);
  NonRigidCpd ref;
  ref.configure(params(), 80, 1000);
  SheetCpd ours;
  ours.configure(params(), g.uv, 1000, 80, 0.0, 40.0);  // cpd.h's cut-off
  CHECK(ours.rank() == 80);
  std::vector<V3> a(80), b(80);
  const auto ra = ref.register_cloud(g.flat, x, a);
  const auto rb = ours.register_cloud(g.flat, {}, x, b);
  REQUIRE(ra.ok);
  REQUIRE(rb.ok);
  CHECK(ra.iterations == rb.iterations);
  double worst = 0;
  for (int i = 0; i < 80; ++i) worst = std::max(worst, (a[i] - b[i]).norm());
  MESSAGE("largest node difference " << worst << " mm after " << rb.iterations << " iterations");
  CHECK(worst < 1e-6);
}

TEST_CASE("the low rank it keeps recovers the bend; hidden nodes take no points") {
  const Grid g = grid(15, 21, 14.0);
  const auto x = cloud(14 * 14.0, 20 * 14.0, 3000, 5);
  SheetCpd cpd;
  cpd.configure(params(), g.uv, 5000);
  MESSAGE("kernel rank " << cpd.rank() << " of " << g.uv.size());
  CHECK(cpd.rank() < static_cast<int>(g.uv.size()) / 2);
  std::vector<V3> y(g.uv.size());
  std::vector<double> p1(g.uv.size());
  const auto r = cpd.register_cloud(g.flat, {}, x, y, p1);
  REQUIRE(r.ok);
  const double before = normal_error(g.flat, g.truth), after = normal_error(y, g.truth);
  MESSAGE("normal error " << before << " -> " << after << " mm, " << r.iterations << " iterations");
  CHECK(after < 1.5);

  // The top third of the rows inactive (as if hidden under a flap): no support there, and the
  // observed nodes still registered.
  std::vector<std::uint8_t> active(g.uv.size(), 1);
  for (std::size_t i = 0; i < active.size(); ++i) active[i] = g.uv[i].y() >= 7 * 14.0;
  const auto r2 = cpd.register_cloud(g.flat, active, x, y, p1);
  REQUIRE(r2.ok);
  for (std::size_t i = 0; i < active.size(); ++i)
    if (!active[i]) CHECK(p1[i] == 0.0);
  CHECK(normal_error(y, g.truth, &active) < 1.5);

  // Allocation-free and deterministic.
  std::vector<V3> y2(g.uv.size());
  std::vector<double> p2(g.uv.size());
  REQUIRE(crease::rt::alloc_hooks_installed());
#if CREASE_COUNT_MALLOC
  g_count_malloc = true;  // the counter sees a malloc
  g_sink = std::malloc(64);
  g_count_malloc = false;
  std::free(g_sink);
  REQUIRE(g_mallocs.exchange(0) == 1);
#endif
  const auto news = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    g_count_malloc = true;
    (void)cpd.register_cloud(g.flat, active, x, y2, p2);
    g_count_malloc = false;
  }
  CHECK(crease::rt::rt_allocation_count() == news);
  CHECK(g_mallocs.load() == 0);
  for (std::size_t i = 0; i < y.size(); ++i) CHECK((y[i] - y2[i]).norm() == 0.0);
}
