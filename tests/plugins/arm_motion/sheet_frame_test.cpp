// The sheet frame from a sheet_state's corner nodes (DESIGN's sheet coordinates).
#include "plugins/arm_motion/sheet_frame.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
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

TEST_CASE("the frame stays with the sheet's base while its far half is folded up") {
  // The world's sheet on a 3 x 5 grid, flat; then the half v > 148.5 turned up about the
  // crease v = 148.5 by 90 deg (the half fold's bend at its second via point).
  auto s = std::make_unique<SheetState>();
  s->nodes_u = 3;
  s->nodes_v = 5;
  auto lay = [&](double bend_rad) {
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 3; ++i) {
        float* p = s->position_mm[j * 3 + i];
        const double v = 74.25 * j, past = std::max(0.0, v - 148.5);
        p[0] = static_cast<float>(-105.0 + 105.0 * i);
        p[1] = static_cast<float>(148.5 - std::min(v, 148.5) - past * std::cos(bend_rad));
        p[2] = static_cast<float>(0.1 + past * std::sin(bend_rad));
      }
  };
  lay(0.0);
  KDL::Frame flat, bent;
  REQUIRE(sheet_frame_m(*s, flat));
  lay(std::numbers::pi / 2);
  REQUIRE(sheet_frame_m(*s, bent));
  CHECK(norm(bent.p - flat.p) < 1e-9);
  CHECK(norm(bent.M.UnitZ() - flat.M.UnitZ()) < 1e-6);
  CHECK(norm(bent.M.UnitY() - flat.M.UnitY()) < 1e-6);
  // From the far corner (node (0, H-1)), as before, the frame would have turned 45 deg.
  const KDL::Vector o(s->position_mm[0][0], s->position_mm[0][1], s->position_mm[0][2]);
  const KDL::Vector c(s->position_mm[12][0], s->position_mm[12][1], s->position_mm[12][2]);
  KDL::Vector x(1, 0, 0), z = x * (c - o);
  z.Normalize();
  CHECK(std::acos(KDL::dot(z, flat.M.UnitZ())) == doctest::Approx(std::numbers::pi / 4).epsilon(0.01));
}

TEST_CASE("the frame stays with the sheet's base when the fold lifts its crease into a loop") {
  // The world's sheet on a 3 x 9 grid, flat; then the nodes on and next to the crease
  // v = 148.5 raised into a loop (30 mm on the crease, 15 mm beside it), as a laid half fold
  // leaves it. The frame is the flat one; from the node halfway along the v edge (on the
  // crease) it would tilt by atan(30 / 148.5), 11 deg.
  auto s = std::make_unique<SheetState>();
  s->nodes_u = 3;
  s->nodes_v = 9;
  auto lay = [&](bool loop) {
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 3; ++i) {
        float* p = s->position_mm[j * 3 + i];
        p[0] = static_cast<float>(-105.0 + 105.0 * i);
        p[1] = static_cast<float>(148.5 - 37.125 * j);
        p[2] = static_cast<float>(0.1 +
                                  (loop ? (j == 4 ? 30.0 : (j == 3 || j == 5 ? 15.0 : 0.0)) : 0.0));
      }
  };
  lay(false);
  KDL::Frame flat, looped;
  REQUIRE(sheet_frame_m(*s, flat));
  lay(true);
  REQUIRE(sheet_frame_m(*s, looped));
  CHECK(norm(looped.p - flat.p) < 1e-9);
  CHECK(norm(looped.M.UnitZ() - flat.M.UnitZ()) < 1e-6);
  // What the crease node would have given.
  const KDL::Vector o(s->position_mm[0][0], s->position_mm[0][1], s->position_mm[0][2]);
  const KDL::Vector c(s->position_mm[12][0], s->position_mm[12][1], s->position_mm[12][2]);
  KDL::Vector z = KDL::Vector(1, 0, 0) * (c - o);
  z.Normalize();
  CHECK(std::acos(KDL::dot(z, flat.M.UnitZ())) ==
        doctest::Approx(std::atan(30.0 / 148.5)).epsilon(0.01));
}
