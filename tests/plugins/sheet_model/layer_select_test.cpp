// The layer-contact select test (layer_select.h): hand-made pairs on both sides, inside and
// outside the reach and the triangle, a degenerate triangle; 8 at a time against one by one
// on random candidates (any count, so the tail runs too).
#include "plugins/sheet_model/layer_select.h"

#include <doctest/doctest.h>

#include <random>
#include <vector>

using namespace crease::sheet;

namespace {

constexpr double kTol = 0.05, kMinArea2 = 1e-12;

struct Scene {
  std::vector<Vec3> x;
  std::vector<std::int32_t> tri;
  std::vector<Vec3> tri_n;
  void add_triangle(int a, int b, int c) {
    tri.insert(tri.end(), {a, b, c});
    tri_n.push_back(cross(x[b] - x[a], x[c] - x[a]));
  }
};

std::vector<LayerPair> run(const Scene& s, const std::vector<LayerPair>& cand, double reach, bool simd) {
  std::vector<LayerPair> out(cand.size());
  const int m = layer_select(cand.data(), static_cast<int>(cand.size()), s.tri.data(), s.x.data(), s.tri_n.data(),
                             reach, kTol, kMinArea2, out.data(), simd);
  out.resize(m);
  return out;
}

}  // namespace

TEST_CASE("a node above, below, beside and too far from a triangle") {
  Scene s;
  s.x = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {5, 5, 0},  // 0-2: a triangle in z = 0; 3, 4, 5: one degenerate
         {2, 2, 0.5}, {2, 2, -0.5}, {20, 20, 0.5}, {2, 2, 3}, {3, 3, 0}, {6, 6, 0}};
  s.add_triangle(0, 1, 2);
  s.add_triangle(3, 8, 9);  // collinear: no normal
  std::vector<LayerPair> cand = {{4, 0, 0}, {5, 0, 0}, {6, 0, 0}, {7, 0, 0}, {4, 1, 0}};
  for (int copies = 0; copies < 3; ++copies) cand.insert(cand.end(), cand.begin(), cand.begin() + 5);  // 20: a group
  for (const bool simd : {false, true}) {
    if (simd && !layer_select_simd_available()) continue;
    const std::vector<LayerPair> got = run(s, cand, 1.0, simd);
    REQUIRE(got.size() == 8);  // per copy: node 4 above (+1), node 5 below (-1)
    for (std::size_t k = 0; k < got.size(); k += 2) {
      CHECK(got[k].node == 4);
      CHECK(got[k].side == 1.0);
      CHECK(got[k + 1].node == 5);
      CHECK(got[k + 1].side == -1.0);
    }
  }
}

TEST_CASE("8 at a time gives what one by one gives, in the same order") {
  if (!layer_select_simd_available()) return;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  Scene s;
  for (int i = 0; i < 60; ++i) s.x.push_back({u(rng), u(rng), 0.2 * u(rng)});
  for (int t = 0; t < 40; ++t) s.add_triangle(t, t + 1 + t % 7, t + 9 + t % 11);
  std::uniform_int_distribution<int> node(0, 59), tri(0, 39);
  for (const int n : {0, 5, 8, 37, 203}) {
    std::vector<LayerPair> cand(n);
    for (LayerPair& c : cand) {
      do {  // not a corner of its own triangle (on its plane: the side would be rounding's choice)
        c = {node(rng), tri(rng), 0.0};
      } while (c.node == s.tri[3 * c.tri] || c.node == s.tri[3 * c.tri + 1] || c.node == s.tri[3 * c.tri + 2]);
    }
    const std::vector<LayerPair> a = run(s, cand, 2.0, true), b = run(s, cand, 2.0, false);
    REQUIRE(a.size() == b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      CHECK(a[k].node == b[k].node);
      CHECK(a[k].tri == b[k].tri);
      CHECK(a[k].side == b[k].side);
    }
    if (n == 203) CHECK(a.size() > 10);  // the random scene has pairs to select
  }
}
