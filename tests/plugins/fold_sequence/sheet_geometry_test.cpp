// What the sequence reads of the tracked sheet: its frame (as arm_motion builds it), a node by
// its sheet coordinates, the model's crease nearest to a line.
#include "plugins/fold_sequence/sheet_geometry.h"

#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <numbers>

using namespace crease;
using namespace crease::fold;

namespace {
// A flat W x H sheet, corner (0, 0) at (x0, y0), turned by yaw about z (u along (cos, sin)).
std::unique_ptr<SheetState> sheet(int w, int h, double x0, double y0, double yaw) {
  auto s = std::make_unique<SheetState>();
  s->nodes_u = static_cast<std::uint16_t>(w);
  s->nodes_v = static_cast<std::uint16_t>(h);
  s->width_mm = 210;
  s->height_mm = 297;
  const double c = std::cos(yaw), sn = std::sin(yaw);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const double u = 210.0 * i / (w - 1), v = 297.0 * j / (h - 1);
      // v runs along the sheet's -y (printed face up: z = u x v into the table).
      float* p = s->position_mm[j * w + i];
      p[0] = static_cast<float>(x0 + c * u + sn * v);
      p[1] = static_cast<float>(y0 + sn * u - c * v);
      p[2] = 0;
    }
  return s;
}
}  // namespace

TEST_CASE("the sheet frame: origin at node (0, 0), x along u, z = u x v into the table") {
  const double yaw = 15 * std::numbers::pi / 180;
  const auto s = sheet(5, 7, -105, 148.5, yaw);
  SheetFrame f;
  REQUIRE(sheet_frame(*s, f));
  CHECK(f.origin[0] == doctest::Approx(-105));
  CHECK(f.origin[1] == doctest::Approx(148.5));
  CHECK(f.x[0] == doctest::Approx(std::cos(yaw)));
  CHECK(f.x[1] == doctest::Approx(std::sin(yaw)));
  CHECK(f.z[2] == doctest::Approx(-1));  // into the table
  CHECK(f.y[0] == doctest::Approx(std::sin(yaw)));  // y along v: the world's -y turned by the yaw
  CHECK(f.y[1] == doctest::Approx(-std::cos(yaw)));
  double p[3];
  REQUIRE(node_at(*s, 210, 297, p));  // the far corner
  CHECK(p[0] == doctest::Approx(-105 + std::cos(yaw) * 210 + std::sin(yaw) * 297).epsilon(1e-6));
  REQUIRE(node_at(*s, 52, 50, p));  // the nearest node: (1, 1) at u 52.5, v 49.5
  CHECK(p[0] == doctest::Approx(-105 + std::cos(yaw) * 52.5 + std::sin(yaw) * 49.5).epsilon(1e-6));
  // A fold file's point (u, v, -h) in the frame: the node itself at h 0, h above it along -z.
  const double at[3] = {52.5, 49.5, -20}, node11[3] = {p[0], p[1], p[2]};
  sheet_to_world(f, at, p);
  CHECK(p[0] == doctest::Approx(node11[0]).epsilon(1e-6));
  CHECK(p[1] == doctest::Approx(node11[1]).epsilon(1e-6));
  CHECK(p[2] == doctest::Approx(20.0));
}

TEST_CASE(
    "the frame takes v a quarter along the edge, as arm_motion's: the far corner a fold lifts does "
    "not tilt it") {
  auto s = sheet(5, 9, -105, 148.5, 0);
  for (int i = 0; i < 5; ++i)
    s->position_mm[8 * 5 + i][2] = -120;  // the far edge carried up and over
  s->position_mm[4 * 5][2] = -30;         // the half fold's crease, looped
  SheetFrame f;
  REQUIRE(sheet_frame(*s, f));
  CHECK(f.z[2] == doctest::Approx(-1));
  CHECK(f.y[1] == doctest::Approx(-1));
  // Failing variant: with node (0, 2) (a quarter along) lifted, the frame tilts.
  s->position_mm[2 * 5][2] = -30;
  REQUIRE(sheet_frame(*s, f));
  CHECK(f.z[2] > -0.95);  // 22 deg
}

TEST_CASE("degenerate sheets have no frame") {
  auto s = sheet(3, 3, 0, 0, 0);
  s->position_mm[2][0] = s->position_mm[0][0];  // node (W-1, 0) on the origin
  s->position_mm[2][1] = s->position_mm[0][1];
  SheetFrame f;
  CHECK_FALSE(sheet_frame(*s, f));
  s = sheet(3, 3, 0, 0, 0);
  s->position_mm[0][2] = std::nanf("");
  CHECK_FALSE(sheet_frame(*s, f));
  s->nodes_u = 1;
  double p[3];
  CHECK_FALSE(node_at(*s, 0, 0, p));
}

TEST_CASE("the model's crease nearest to the intended line, in the line's direction") {
  auto s = sheet(3, 3, 0, 0, 0);
  double a[2] = {0, 148.5}, b[2] = {210, 148.5};
  CHECK_FALSE(nearest_crease(*s, a, b));  // none: the line is left as it is
  CHECK(a[1] == 148.5);
  s->crease_count = 2;
  const float far[4] = {0, 20, 210, 20};
  const float near_flipped[4] = {210, 150, 0, 147};
  for (int c = 0; c < 4; ++c) {
    s->crease_mm[0][c] = far[c];
    s->crease_mm[1][c] = near_flipped[c];
  }
  REQUIRE(nearest_crease(*s, a, b));
  CHECK(a[0] == 0);
  CHECK(a[1] == 147);
  CHECK(b[0] == 210);
  CHECK(b[1] == 150);
}

// A fold file's world-frame point (grasp above_via, `frame: world`) goes out in the sheet frame:
// world_to_sheet inverts sheet_to_world, and turns a world orientation into the frame's. The
// simulated robot's sheet as laid (corner (0, 0) at (105, -148.5), u along -x, v along +y): the
// half fold's above_via, given in the world as (200, -150, 300) mm, is the sheet point
// (-95, -1.5, -300) with the orientation the file gave before in the sheet frame.
TEST_CASE("world_to_sheet: a world pose in the sheet frame, the inverse of sheet_to_world") {
  const auto s = sheet(3, 3, 105, -148.5, std::numbers::pi);  // u along -x, v along +y
  SheetFrame f;
  REQUIRE(sheet_frame(*s, f));
  const double w[3] = {200, -150, 300}, qw[4] = {0.05114, 0.50756, -0.08625, 0.85576};
  double p[3], q[4];
  world_to_sheet(f, w, qw, p, q);
  CHECK(p[0] == doctest::Approx(-95.0));
  CHECK(p[1] == doctest::Approx(-1.5));
  CHECK(p[2] == doctest::Approx(-300.0));
  const double was[4] = {0.08625, -0.85576, 0.05114, 0.50756};  // the same pose as a sheet point
  const double sign = q[3] * was[3] < 0 ? -1.0 : 1.0;           // q and -q are one turn
  for (int c = 0; c < 4; ++c) CHECK(sign * q[c] == doctest::Approx(was[c]).epsilon(1e-4));
  double back[3];
  sheet_to_world(f, p, back);
  for (int c = 0; c < 3; ++c) CHECK(back[c] == doctest::Approx(w[c]));
  // Turned 15 deg more, the same world pose is another sheet pose.
  const auto t = sheet(3, 3, 105, -148.5, std::numbers::pi + 15 * std::numbers::pi / 180);
  SheetFrame g;
  REQUIRE(sheet_frame(*t, g));
  world_to_sheet(g, w, qw, p, q);
  sheet_to_world(g, p, back);
  for (int c = 0; c < 3; ++c) CHECK(back[c] == doctest::Approx(w[c]));
  CHECK(std::fabs(p[1] + 1.5) > 20.0);  // 95 mm out along u, turned 15 deg: 24.6 mm across
}

// The sequence's goals from the lay on go out as world poses (the frame held from the bend):
// sheet_to_world of a pose is world_to_sheet's inverse, orientation included.
TEST_CASE("sheet_to_world: a sheet pose in the world, the inverse of world_to_sheet") {
  const auto s = sheet(3, 3, 105, -148.5, std::numbers::pi + 0.2);
  SheetFrame f;
  REQUIRE(sheet_frame(*s, f));
  const double p[3] = {165, 40, -30}, q[4] = {0.18301, -0.18301, 0.68301, 0.68301};
  double w[3], qw[4], back[3], qb[4];
  sheet_to_world(f, p, q, w, qw);
  CHECK(w[2] == doctest::Approx(30.0));  // 30 mm over the table: the frame's z points into it
  world_to_sheet(f, w, qw, back, qb);
  for (int c = 0; c < 3; ++c) CHECK(back[c] == doctest::Approx(p[c]));
  const double sign = qb[3] * q[3] < 0 ? -1.0 : 1.0;
  for (int c = 0; c < 4; ++c) CHECK(sign * qb[c] == doctest::Approx(q[c]).epsilon(1e-9));
  // The identity (a pad pressing down onto the sheet) is the frame's own turn: its z into the
  // table.
  const double id[4] = {0, 0, 0, 1};
  sheet_to_world(f, p, id, w, qw);
  const double z_down = 1.0 - 2.0 * (qw[0] * qw[0] + qw[1] * qw[1]);  // R(q)'s zz
  CHECK(z_down == doctest::Approx(-1.0));
}

TEST_CASE(
    "frame_yaw is the heading of u; turn_about_vertical turns a sheet-frame pose about the world's "
    "z") {
  const double yaw = std::numbers::pi + 0.2;
  const auto s = sheet(3, 3, 105, -148.5, yaw);
  SheetFrame f;
  REQUIRE(sheet_frame(*s, f));
  CHECK(std::remainder(frame_yaw(f) - yaw, 2 * std::numbers::pi) ==
        doctest::Approx(0.0).epsilon(1e-6));
  // Turning a pose by -0.2 rad about the vertical in this frame is the same world pose as that
  // pose in the frame of the sheet turned 0.2 rad less.
  const auto s0 = sheet(3, 3, 105, -148.5, std::numbers::pi);
  SheetFrame f0;
  REQUIRE(sheet_frame(*s0, f0));
  const double p[3] = {0, 0, 0}, q[4] = {-0.52423, 0.70760, -0.28017, -0.38208};
  double turned[4], w1[3], q1[4], w0[3], q0[4];
  turn_about_vertical(f, -0.2, q, turned);
  sheet_to_world(f, p, turned, w1, q1);
  sheet_to_world(f0, p, q, w0, q0);
  const double sign = q1[3] * q0[3] < 0 ? -1.0 : 1.0;
  for (int c = 0; c < 4; ++c) CHECK(sign * q1[c] == doctest::Approx(q0[c]).epsilon(1e-6));
  // No turn: the same orientation.
  double same[4];
  turn_about_vertical(f, 0.0, q, same);
  for (int c = 0; c < 4; ++c) CHECK(same[c] == doctest::Approx(q[c]).epsilon(1e-9));
}

TEST_CASE(
    "the point of a folded part under a world point: the part's nearest node, refined within its "
    "cell") {
  // 15 x 21 nodes (15 x 14.85 mm cells), flat, u along +x, v along -y; then the far half
  // (v > 148.5) folded flat over the near half, 1 mm up: node (i, j) over node (i, 20 - j).
  auto s = sheet(15, 21, 0, 0, 0.0);
  for (int j = 11; j < 21; ++j)
    for (int i = 0; i < 15; ++i)
      for (int c = 0; c < 3; ++c)
        s->position_mm[j * 15 + i][c] =
            s->position_mm[(20 - j) * 15 + i][c] + (c == 2 ? 1.0f : 0.0f);
  const double a[2] = {0, 148.5}, b[2] = {210, 148.5}, far_side[2] = {105, 282.5};
  double uv[2];
  // Over sheet point (100, 40) of the near half, i.e. (100, 257) of the folded one.
  const double p[3] = {100, -40, 5};
  REQUIRE(part_point_under(*s, a, b, far_side, p, 22.5, uv));
  CHECK(uv[0] == doctest::Approx(100.0));
  CHECK(uv[1] == doctest::Approx(257.0));
  // The near part asked for: the near half's own point.
  const double near_side[2] = {105, 10};
  REQUIRE(part_point_under(*s, a, b, near_side, p, 22.5, uv));
  CHECK(uv[1] == doctest::Approx(40.0));
  // Unfolded, the far half lies beyond y = -148.5: nothing of it within reach of p.
  const auto flat = sheet(15, 21, 0, 0, 0.0);
  CHECK_FALSE(part_point_under(*flat, a, b, far_side, p, 22.5, uv));
  // Over the line: the part's nearest node is the next row (the line's own nodes belong to
  // neither part), and its cell's step reaches the line.
  const double on_line[3] = {105, -148.5, 0};
  REQUIRE(part_point_under(*flat, a, b, far_side, on_line, 22.5, uv));
  CHECK(uv[0] == doctest::Approx(105.0));
  CHECK(uv[1] == doctest::Approx(148.5));
  const double degenerate[2] = {0, 148.5};
  CHECK_FALSE(part_point_under(*s, a, degenerate, far_side, p, 22.5, uv));
}
