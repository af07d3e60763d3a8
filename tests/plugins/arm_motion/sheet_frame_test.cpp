// The sheet frame from a sheet_state's corner nodes (DESIGN's sheet coordinates).
#include "plugins/arm_motion/sheet_frame.h"

#include <doctest/doctest.h>

#include <cmath>
#include <memory>

using namespace crease;
using namespace crease::arm_motion;

namespace {
double norm(const KDL::Vector& v) { return std::sqrt(KDL::dot(v, v)); }  // KDL's Norm reads < 1e-6 as 0
}  // namespace

TEST_CASE("origin at node (0, 0), x along u, z = u x v; degenerate states are refused") {
  auto s = std::make_unique<SheetState>();
  s->nodes_u = 3;
  s->nodes_v = 2;
  // The world sheet of sim_world: u along +x, v along -y, lying flat at z = 0.1 mm.
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 3; ++i) {
      float* p = s->position_mm[j * 3 + i];
      p[0] = -105.0f + 105.0f * i;
      p[1] = 148.5f - 297.0f * j;
      p[2] = 0.1f;
    }
  KDL::Frame f;
  REQUIRE(sheet_frame_m(*s, f));
  CHECK(norm((f.p - KDL::Vector(-0.105, 0.1485, 0.0001))) < 1e-9);
  CHECK(norm((f.M.UnitX() - KDL::Vector(1, 0, 0))) < 1e-9);
  CHECK(norm((f.M.UnitY() - KDL::Vector(0, -1, 0))) < 1e-9);
  CHECK(norm((f.M.UnitZ() - KDL::Vector(0, 0, -1))) < 1e-9);  // into the table: away from the print
  // (u, v) = (210, 297) mm is the far corner.
  CHECK(norm((f * KDL::Vector(0.210, 0.297, 0) - KDL::Vector(0.105, -0.1485, 0.0001))) < 1e-6);
  s->position_mm[2][0] = s->position_mm[0][0];  // node (W-1, 0) on the origin
  s->position_mm[2][1] = s->position_mm[0][1];
  CHECK_FALSE(sheet_frame_m(*s, f));
  s->position_mm[2][0] = NAN;
  CHECK_FALSE(sheet_frame_m(*s, f));
  s->nodes_v = 1;
  CHECK_FALSE(sheet_frame_m(*s, f));
}
