// The observed surface's normal at depth targets on grid nodes (depth_surface_normals.h):
// central differences of the neighbours' targets, one-sided at a missing neighbour, none where
// a direction has no neighbour or the two directions are near parallel; targets off the grid
// get none.
#include "plugins/sheet_model/depth_surface_normals.h"

#include <doctest/doctest.h>

#include <cmath>
#include <vector>

using namespace crease::sheet;

namespace {

constexpr int kW = 5, kH = 4;
constexpr double kStep = 15.0;  // mm between nodes

// Targets on every node of a W x H grid lying on the plane through the origin spanned by
// U and V (the images of the sheet's u and v axes, unit vectors scaled by kStep per node).
struct Cloud {
  std::vector<NormalTarget> t;
  std::vector<std::int32_t> node;
  std::vector<std::int32_t> scratch = std::vector<std::int32_t>(kW * kH, 7);
  Cloud(Vec3 u, Vec3 v) {
    for (int j = 0; j < kH; ++j)
      for (int i = 0; i < kW; ++i) {
        NormalTarget n;
        n.world_mm = (i * kStep) * u + (j * kStep) * v;
        n.sheet_mm = {i * kStep, j * kStep};
        n.surface_normal = {9, 9, 9};  // overwritten
        t.push_back(n);
        node.push_back(j * kW + i);
      }
  }
  void drop(int i, int j) {  // no target on node (i, j): its entry is moved off the grid
    node[j * kW + i] = -1;
  }
  void run() { estimate_surface_normals_rt(kW, kH, t, node, scratch); }
  [[nodiscard]] const Vec3& at(int i, int j) const { return t[j * kW + i].surface_normal; }
};

bool near(const Vec3& a, const Vec3& b) {
  return norm(a - b) < 1e-9;
}

}  // namespace

TEST_CASE("a plane's normal at every target, inner nodes and edges alike, on u x v's side") {
  const double c = std::cos(0.5), s = std::sin(0.5);
  const Vec3 u{c, 0, s}, v{0, 1, 0};  // the plane tilted 0.5 rad about y
  Cloud cl(u, v);
  cl.run();
  const Vec3 expect = normalized(cross(u, v));
  for (int j = 0; j < kH; ++j)
    for (int i = 0; i < kW; ++i) {
      CAPTURE(i);
      CAPTURE(j);
      CHECK(near(cl.at(i, j), expect));
    }
  // Laid out as the world lays the sheet (u along x, v along -y): u x v, so -z.
  Cloud flat({1, 0, 0}, {0, -1, 0});
  flat.run();
  CHECK(near(flat.at(2, 1), {0, 0, -1}));
}

TEST_CASE(
    "a missing neighbour: the one-sided difference; both along one direction missing: no normal") {
  Cloud cl({1, 0, 0}, {0, 1, 0});
  cl.drop(1, 1);  // (2, 1) loses its left neighbour, (1, 2) its lower one
  cl.drop(3, 1);  // (2, 1) loses its right one too: nothing along u
  cl.run();
  CHECK(near(cl.at(2, 1), {}));
  CHECK(near(cl.at(1, 2), {0, 0, 1}));
  CHECK(near(cl.at(1, 1), {}));  // itself off the grid: none
  // A bent sheet: the row j = 1 lifted 10 mm; the node (0, 0) sees it one-sided, (2, 2) centrally.
  Cloud bent({1, 0, 0}, {0, 1, 0});
  for (int i = 0; i < kW; ++i) bent.t[1 * kW + i].world_mm.z += 10.0;
  bent.run();
  CHECK(near(bent.at(0, 0), normalized(cross(Vec3{1, 0, 0}, Vec3{0, kStep, 10.0}))));
  CHECK(near(bent.at(2, 2), normalized(cross(Vec3{1, 0, 0}, Vec3{0, 2 * kStep, -10.0}))));
}

TEST_CASE(
    "directions within 30 deg of parallel give no normal; a target node outside the grid is "
    "ignored") {
  // v turned to 25 deg from u: |u x v| = sin 25 < 0.5.
  const double a = 25.0 * 3.14159265358979323846 / 180.0;
  Cloud cl({1, 0, 0}, {std::cos(a), std::sin(a), 0});
  cl.run();
  CHECK(near(cl.at(2, 1), {}));
  // 35 deg: a normal.
  const double b = 35.0 * 3.14159265358979323846 / 180.0;
  Cloud ok({1, 0, 0}, {std::cos(b), std::sin(b), 0});
  ok.run();
  CHECK(near(ok.at(2, 1), {0, 0, 1}));
  // A node index past the grid: no normal for it, and no write outside the scratch.
  Cloud bad({1, 0, 0}, {0, 1, 0});
  bad.node[0] = kW * kH + 3;
  bad.run();
  CHECK(near(bad.at(0, 0), {}));
  CHECK(near(bad.at(2, 1), {0, 0, 1}));
}
