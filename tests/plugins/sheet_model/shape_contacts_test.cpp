// Node-against-shape contacts: push-out, static and sliding friction by hand, pinned nodes,
// and the 8-at-a-time path against the one-by-one path (also with a node in two contacts).
#include "plugins/sheet_model/shape_contacts.h"

#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace crease::sheet;

namespace {

constexpr double kHalf = 0.5;  // half thickness, mm
const Vec3 kUp{0, 0, 1};

struct Case {
  std::vector<Vec3> x, prev;
  std::vector<double> w;
};

}  // namespace

TEST_CASE("a node below the table is pushed out; friction holds a small slide and shortens a large one") {
  for (const bool scalar : {false, true}) {
    ShapeContacts c;
    c.reserve(4);
    c.force_scalar(scalar);
    // node 0: sank 0.2 below the surface, slid 0.05 (static: 0.05 <= 0.5 * 0.2);
    // node 1: sank 0.2, slid 3 (sliding: shortened by 0.1); node 2: above, untouched;
    // node 3: pinned.
    std::vector<Vec3> prev = {{0, 0, 0.5}, {0, 0, 0.5}, {0, 0, 2}, {0, 0, 0.5}};
    std::vector<Vec3> x = {{0.05, 0, 0.3}, {3, 0, 0.3}, {1, 0, 1.5}, {1, 0, 0.3}};
    const std::vector<double> w = {1, 1, 1, 0};
    for (int i = 0; i < 4; ++i) CHECK(c.push(i, kUp, 0.0));
    c.solve_rt(x, prev, w, kHalf, 0.5);
    CHECK(x[0].x == doctest::Approx(0.0));
    CHECK(x[0].z == doctest::Approx(0.5));
    CHECK(x[1].x == doctest::Approx(3.0 - 0.1));
    CHECK(x[1].z == doctest::Approx(0.5));
    CHECK(x[2].x == 1.0);
    CHECK(x[2].z == 1.5);
    CHECK(x[3].z == 0.3);
  }
}

TEST_CASE("the capacity is kept: a push beyond it is refused") {
  ShapeContacts c;
  c.reserve(3);
  CHECK(c.capacity() >= 3);
  int pushed = 0;
  while (c.push(pushed, kUp, 0.0)) ++pushed;
  CHECK(pushed == c.capacity());
  c.clear();
  CHECK(c.size() == 0);
}

TEST_CASE("8 contacts at a time agree with one by one, with slanted shapes and a node in two contacts") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const bool twice : {false, true}) {
    const int n = 203;  // not a multiple of 8
    Case a;
    for (int i = 0; i < n; ++i) {
      a.prev.push_back({10.0 * i, u(rng), 0.5 + 0.3 * u(rng)});
      a.x.push_back(a.prev.back() + Vec3{0.3 * u(rng), 0.3 * u(rng), 0.4 * u(rng) - 0.2});
      a.w.push_back(i % 17 == 0 ? 0.0 : 1.0 + 0.5 * u(rng));
    }
    ShapeContacts vec, one;
    vec.reserve(2 * n);
    one.reserve(2 * n);
    one.force_scalar(true);
    for (int i = 0; i < n; ++i) {
      const Vec3 nrm = normalized(Vec3{0.2 * u(rng), 0.2 * u(rng), 1.0});
      const double off = 0.1 * u(rng);
      vec.push(i, nrm, off);
      one.push(i, nrm, off);
      if (twice && i % 5 == 0) {  // a second shape under the same node
        const Vec3 n2 = normalized(Vec3{1.0, 0.0, 0.3});
        vec.push(i, n2, dot(n2, a.prev[i]) - 0.2);
        one.push(i, n2, dot(n2, a.prev[i]) - 0.2);
      }
    }
    const std::vector<Vec3> before = a.x;
    Case b = a;
    vec.solve_rt(a.x, a.prev, a.w, kHalf, 0.4);
    one.solve_rt(b.x, b.prev, b.w, kHalf, 0.4);
    double diff = 0, moved = 0;
    for (int i = 0; i < n; ++i) {
      diff = std::max(diff, norm(a.x[i] - b.x[i]));
      moved = std::max(moved, norm(a.x[i] - before[i]));
      if (a.w[i] == 0) CHECK(norm(a.x[i] - before[i]) == 0.0);  // pinned: left alone
    }
    CHECK(moved > 0.1);
    CHECK(diff < 1e-12);  // fused multiply-adds only
  }
}
