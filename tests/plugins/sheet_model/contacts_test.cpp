// Self-collision detection (contacts.h) against a brute-force reference of the same rule:
// node p and triangle t pair when p is not within kSelfSkipCells + 1 grid cells of t's
// first corner, lies within thickness + margin of t's plane, and projects inside t
// (barycentric tolerance 0.05); degenerate and torn triangles are skipped.
#include "plugins/sheet_model/contacts.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "plugins/sim_world/scene/fold_script.h"

using namespace crease::sheet;

namespace {

int reference_pairs(const Topology& topo, const GridParams& gp, const std::vector<Vec3>& x, double margin) {
  const double reach = gp.thickness_mm + margin;
  const double cell = std::hypot(topo.grid.du, topo.grid.dv) + 2.0 * gp.thickness_mm;
  const int w = topo.grid.w;
  int count = 0;
  for (int t = 0; t < topo.triangle_count(); ++t) {
    const Vec3 a = x[topo.tri[3 * t]], b = x[topo.tri[3 * t + 1]], c = x[topo.tri[3 * t + 2]];
    const Vec3 n = cross(b - a, c - a);
    const double nn = dot(n, n);
    if (!(nn > 1e-12)) continue;
    bool torn = false;
    const double lo[3] = {std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y}), std::min({a.z, b.z, c.z})};
    const double hi[3] = {std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y}), std::max({a.z, b.z, c.z})};
    for (int e = 0; e < 3; ++e)
      torn = torn || std::floor((hi[e] + reach) / cell) - std::floor((lo[e] - reach) / cell) > 3;
    if (torn) continue;
    const int ti = topo.tri[3 * t] % w, tj = topo.tri[3 * t] / w;
    for (int p = 0; p < topo.grid.count(); ++p) {
      if (std::abs(p % w - ti) <= 3 && std::abs(p / w - tj) <= 3) continue;
      const double d = dot(x[p] - a, (1.0 / std::sqrt(nn)) * n);
      if (std::fabs(d) >= reach) continue;
      const double ba = dot(cross(b - x[p], c - x[p]), n) / nn, bb = dot(cross(c - x[p], a - x[p]), n) / nn;
      if (ba >= -0.05 && bb >= -0.05 && 1.0 - ba - bb >= -0.05) ++count;
    }
  }
  return count;
}

}  // namespace

TEST_CASE("self-collision candidates match a brute-force reference, with and without AVX2 screening") {
  GridParams gp;
  const Topology topo = build_topology(gp, TopologyParams{});
  SolverParams sp;
  std::vector<Vec3> x(topo.grid.count());
  std::mt19937 rng(3);
  std::normal_distribution<double> jitter(0.0, 0.3);
  int checked = 0;
  for (const FoldScript& script : {FoldScript::half_fold(gp), FoldScript::diagonal_fold(gp), FoldScript::two_folds(gp)}) {
    for (const double frac : {0.5, 0.7, 0.9, 1.0}) {
      script.node_positions(frac * script.duration_s(), x);
      for (Vec3& p : x) p += Vec3{jitter(rng), jitter(rng), jitter(rng)};
      for (const double margin : {2.0, 8.0}) {
        const int ref = reference_pairs(topo, gp, x, margin);
        ContactSolver simd, scalar;
        simd.configure(topo, gp, sp);
        scalar.configure(topo, gp, sp);
        scalar.force_scalar(true);
        simd.detect_rt(x, nullptr, margin);
        scalar.detect_rt(x, nullptr, margin);
        // Fresh solvers: `dropped` counts the candidates beyond the buffer in this call.
        CHECK(simd.stats().self_pairs + static_cast<int>(simd.stats().dropped) == ref);
        CHECK(scalar.stats().self_pairs + static_cast<int>(scalar.stats().dropped) == ref);
        checked += ref > 0;
      }
    }
  }
  CHECK(checked > 5);  // folded layers do come close
}

TEST_CASE("candidates kept from a wider detection select what a fresh detection finds after a move (8 at a time and one by one)") {
  // Detection with the margin plus a skin (and the skin beside each triangle), then every
  // node moved by up to half the skin: select_rt must give exactly the pairs a fresh
  // detection with the frame's margin gives (a pair missed by the wide detection fails it).
  GridParams gp;
  const Topology topo = build_topology(gp, TopologyParams{});
  SolverParams sp;
  std::vector<Vec3> x(topo.grid.count()), moved(topo.grid.count());
  std::mt19937 rng(11);
  std::normal_distribution<double> jitter(0.0, 0.3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  constexpr double kMargin = 2.0, kSkin = 4.0;
  int checked = 0;
  for (const FoldScript& script : {FoldScript::half_fold(gp), FoldScript::diagonal_fold(gp), FoldScript::two_folds(gp)}) {
    for (const double frac : {0.6, 0.8, 0.95, 1.0}) {
      script.node_positions(frac * script.duration_s(), x);
      for (Vec3& p : x) p += Vec3{jitter(rng), jitter(rng), jitter(rng)};
      for (std::size_t i = 0; i < x.size(); ++i) {
        Vec3 d{unit(rng), unit(rng), unit(rng)};
        if (norm(d) > 1.0) d = normalized(d);
        moved[i] = x[i] + (0.5 * kSkin) * d;
      }
      ContactSolver kept, fresh, one_by_one;
      kept.configure(topo, gp, sp);
      fresh.configure(topo, gp, sp);
      one_by_one.configure(topo, gp, sp);
      one_by_one.force_scalar(true);  // no AVX2 screening, no AVX-512 select
      kept.detect_rt(x, nullptr, kMargin + kSkin, kSkin);
      one_by_one.detect_rt(x, nullptr, kMargin + kSkin, kSkin);
      REQUIRE(kept.stats().dropped == 0);
      CHECK(kept.stats().self_candidates >= kept.stats().self_pairs);
      CHECK(one_by_one.stats().self_candidates == kept.stats().self_candidates);
      kept.select_rt(moved, kMargin);
      one_by_one.select_rt(moved, kMargin);
      fresh.detect_rt(moved, nullptr, kMargin);
      const int ref = reference_pairs(topo, gp, moved, kMargin);
      CHECK(fresh.stats().self_pairs == ref);
      CHECK(kept.stats().self_pairs == ref);
      CHECK(one_by_one.stats().self_pairs == ref);
      checked += ref > 0;
    }
  }
  CHECK(checked > 5);
}

TEST_CASE("without the skin beside the triangles, sliding nodes lose their candidates") {
  // The same kind of move after a detection with no lateral allowance: some pairs are
  // missed, which is why XpbdSheet detects with one (and shows the test above can fail).
  GridParams gp;
  const Topology topo = build_topology(gp, TopologyParams{});
  SolverParams sp;
  std::vector<Vec3> x(topo.grid.count()), moved(topo.grid.count());
  int kept_total = 0, ref_total = 0;
  for (const FoldScript& script : {FoldScript::half_fold(gp), FoldScript::diagonal_fold(gp), FoldScript::two_folds(gp)}) {
    for (const double frac : {0.6, 0.8, 0.95, 1.0}) {
      script.node_positions(frac * script.duration_s(), x);
      for (std::size_t i = 0; i < x.size(); ++i) moved[i] = x[i] + Vec3{(i % 2 == 0 ? 2.0 : -2.0), 0.0, 0.0};
      ContactSolver kept;
      kept.configure(topo, gp, sp);
      kept.detect_rt(x, nullptr, 6.0, 0.0);
      kept.select_rt(moved, 2.0);
      kept_total += kept.stats().self_pairs;
      ref_total += reference_pairs(topo, gp, moved, 2.0);
    }
  }
  MESSAGE("kept " << kept_total << " of " << ref_total);
  CHECK(ref_total > 0);
  CHECK(kept_total < ref_total);
}

namespace {

// The half fold flat (the far half on top of the near one), the top layer pressed 0.3 mm into
// the bottom one while the bottom layer moves 1 mm along x in a substep (a hand drags the stack).
// Returns how far the top layer's nodes moved along x on average (mm) after one solve_rt with
// layer friction MU.
double top_layer_drag_mm(double mu) {
  GridParams gp;
  const Topology topo = build_topology(gp, TopologyParams{});
  SolverParams sp;
  sp.layer_friction = mu;
  const FoldScript script = FoldScript::half_fold(gp);
  std::vector<Vec3> x(topo.grid.count());
  script.node_positions(0.0, x);  // flat
  // The far rows laid mirrored onto the near ones, 0.7 x the thickness over them (0.3 of it deep).
  const int w_nodes = topo.grid.w, h_nodes = topo.grid.count() / topo.grid.w;
  const double z0 = x[0].z;
  for (int j = (h_nodes + 1) / 2; j < h_nodes; ++j)
    for (int i = 0; i < w_nodes; ++i) {
      Vec3& p = x[static_cast<std::size_t>(j * w_nodes + i)];
      p = x[static_cast<std::size_t>((h_nodes - 1 - j) * w_nodes + i)];
      p.z = z0 + 0.7 * gp.thickness_mm;
    }
  const double mid_z = z0 + 0.35 * gp.thickness_mm;
  ContactSolver solver;
  solver.configure(topo, gp, sp);
  solver.detect_rt(x, nullptr, 2.0);
  REQUIRE(solver.stats().self_pairs > 0);
  std::vector<Vec3> prev = x;
  std::vector<double> w(x.size(), 1.0);
  std::vector<bool> top(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    top[i] = x[i].z > mid_z;
    if (!top[i]) x[i].x += 1.0;
  }
  const std::vector<Vec3> before = x;
  solver.solve_rt(x, prev, w);
  double moved = 0;
  int n = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (top[i]) {
      moved += x[i].x - before[i].x;
      ++n;
    }
  return moved / n;
}

}  // namespace

// Paper on paper (the world's sheet: its drawn paper-paper coefficient): a layer pressed onto
// another is carried along by it, by at most the coefficient times the depth each contact
// corrected; frictionless layers slide freely (the failing variant, the tracking model's default).
TEST_CASE(
    "layer friction: a layer pressed onto a moving one is dragged along; without friction it is "
    "not") {
  const double dragged = top_layer_drag_mm(0.4);
  MESSAGE("top layer dragged " << dragged << " mm by the bottom layer's 1 mm (friction 0.4)");
  CHECK(dragged > 0.01);
  CHECK(dragged < 0.4 * 0.3 + 1e-9);  // at most mu x depth: kinetic, a 1 mm slip beats 0.12 mm
  // Frictionless: only the pushes of the slanted cells by the crease move it along x, ~2 % of that.
  CHECK(std::fabs(top_layer_drag_mm(0.0)) < 0.05 * dragged);
}
