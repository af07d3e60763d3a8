// Bending the sheet over into a half fold while the other hand fixates it (seed 000 Fig. 7b-d):
// the right hand pinches the middle of the sheet's far edge (overhanging the table's far edge)
// between thumb and index, the left index presses the near half onto the table, and the pinch
// is carried over the crease line (y = the sheet's centre) on a half circle of radius 134 mm
// (15 % shorter at the top, so the sheet bends in a loop instead of being pulled taut), turning
// with the sheet by up to 120 deg, and laid down by the near edge; the left index then slides
// out from under the top layer, off the sheet's side. Scored from the world's sheet: the far edge
// lies over the near one (mean distance in x, y over the 29 columns) and the far half lies on
// top of the near half.
//
// The scene: the shipped robot (config/robot: the arms 1 m over the table, 300 mm behind the
// sheet's centre) and the sheet where the world lays it, the table's far edge 53.5 mm inside the
// sheet's far edge. (With the arms 1.3 m over the table and 450 mm behind, the mounts before,
// the PA-10's elbow stretched straight before the pinch had turned 60 deg; carried away from the
// robot (the near edge over to the far one) the turning hand's wrist moves away from the
// shoulder and the elbow straightens too.)
// Failing variants: frictionless fingers: the pinch loses the edge at ~60 deg and it falls back;
// the left index not pressing: the pinch drags the near half after it. And the grasp of
// config/folds/half.yaml: from beyond the far edge, round its drooping overhang (failing variant:
// straight in at the pinch's height, into the hanging edge).
// The scenes are open-loop and chaotic where the pinch holds the sheet (by one to three 7.5 mm
// nodes): where the far edge lands moves by several mm with the last bits of the arithmetic
// (the sheet's link pass 16 or 8 links at a time, as the CPU has AVX-512 or not; libm's FMA or
// plain path: 5.3-12.1 mm for the first fold, 7.9-20.5 mm for the grasp from beyond, over those
// and pinch points 0.5 mm apart); "folded" is within 25 mm (a dropped edge: ~290 mm).
// The release of the laid layer (config/folds/half.yaml's (d)-(f)) is not a test here: whether
// the pinch still holds the layer when it is laid, and whether opening and withdrawing leave the
// fold or drag it, turn on those bits (plugins/sim_world/README.md has the figures).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "plugins/sim_world/reference_poses.h"
#include "scene.h"

using namespace scene;

namespace {

constexpr double kTableMm = 0.0;    // the table's top (z): sim_world's
constexpr double kSheetDyMm = 0.0;   // the sheet's centre (y): its far edge at y = 148.5
constexpr double kCloseThj5 = 0.77;  // the pinch squeezes (reference_poses.h: 0.696 touches)

int nearest_node(const World& w, Vec3 p) {
  const auto x = w.sheet().positions();
  int best = 0;
  for (int i = 1; i < static_cast<int>(x.size()); ++i)
    if (sheet::norm(x[i] - p) < sheet::norm(x[best] - p)) best = i;
  return best;
}

struct Fold {
  double pinch_n = 0;         // the squeeze once closed
  double worst_slip_mm = 0;   // of the pinched node against the index pad, over the fold
  double near_drag_mm = 0;    // how far the near edge moved (the fixation's hold)
  double edges_apart_mm = 0;  // mean over the columns: far-edge node to near-edge node, in x, y
  double peak_n = 0;          // the highest normal force on a pinching fingertip over the fold (what its taxels read)
  double on_top = 0;          // fraction of the far half's nodes (rows 0-15) above their mirror node (40 - row) by > 0.5 mm
  double worst_stretch = 0;   // the grid's largest edge stretch over the fold (every 50 ms; 0.1: 10 %)
};

double edges_apart(const World& w) {
  const auto x = w.sheet().positions();
  const sheet::Grid& g = w.sheet().grid();
  double d = 0;
  for (int i = 0; i < g.w; ++i) {
    const Vec3 a = x[g.index(i, 0)], e = x[g.index(i, g.h - 1)];
    d += std::hypot(a.x - e.x, a.y - e.y);
  }
  return d / g.w;
}

double on_top(const World& w) {
  const auto x = w.sheet().positions();
  const sheet::Grid& g = w.sheet().grid();
  int n = 0, over = 0;
  for (int j = 0; j <= 15; ++j)
    for (int i = 0; i < g.w; ++i, ++n)
      if (x[g.index(i, j)].z > x[g.index(i, g.h - 1 - j)].z + 0.5) ++over;
  return static_cast<double>(over) / n;
}

double near_edge_y(const World& w) {
  const auto x = w.sheet().positions();
  const sheet::Grid& g = w.sheet().grid();
  double y = 0;
  for (int i = 0; i < g.w; ++i) y += x[g.index(i, g.h - 1)].y;
  return y / g.w;
}

// How the pinching hand gets to the pinch. The default: it starts there, the index pad 8 mm under
// the overhang (53.5 mm over the table's edge at y = 95). FROM_BEYOND (config/folds/half.yaml's
// grasp): the table's edge at y = 115 (33.5 mm of overhang, drooping ~20 mm), the hand starts 40 mm
// over the table beyond the far edge, the thumb open at THJ5 OPEN_THJ5, and goes round the
// overhang: down to UNDER_MM under the table top, in under the sheet, then up to the pinch.
struct Grasp {
  bool from_beyond = false;
  double table_edge_y_mm = 95.0;
  double open_thj5 = 0.3;
  double under_mm = 8.0;
};

Grasp from_beyond(double under_mm) { return {true, 115.0, 0.0, under_mm}; }

// FIXATE false: the left index hovers 8 mm over the near half instead of pressing it.
Fold fold(WorldParams p, Bimanual& b, bool fixate = true, const Grasp& grasp = {}) {
  REQUIRE(p.table_height_mm == kTableMm);
  REQUIRE(p.sheet.grid.origin_mm.y == 148.5 + kSheetDyMm);
  p.table_extent_mm = {-WorldParams::kNoEdge, WorldParams::kNoEdge, -WorldParams::kNoEdge,
                       grasp.table_edge_y_mm + kSheetDyMm};
  b.params = p;
  // The pinch (reference_poses.h) turned about z to reach the far edge from beyond it, the index
  // pad under the overhang, 14.5 mm inside the far edge's middle; 3 N m/rad.
  const Vec3 at{0, 134.0 + kSheetDyMm, kTableMm - 8};
  b.r.q = poses::pinch_hand(grasp.open_thj5);
  b.r.palm = KDL::Rotation::RotZ(std::numbers::pi) * poses::pinch_palm(robot_model(), poses::pinch_hand(0.696));
  b.r.at = grasp.from_beyond ? Vec3{at.x, 190.0 + kSheetDyMm, kTableMm + 40} : at;
  b.r.k.fill(3.0);
  // The left index over the near half, 60 mm from its left and 60 mm from the crease; 3 N m/rad.
  b.l.q = poses::index_out();
  b.l.palm = poses::palm_forward_down(deg(30));
  b.l.at = {-60, -60 + kSheetDyMm, kTableMm + 8};
  b.l.k.fill(3.0);
  b.start();
  b.hold(0.3);
  // The left index down to contact at 10 mm/s, then 8 mm further (0.76 N).
  while (fixate && b.l.at.z > kTableMm - 3 && b.hand(Side::left).tip[0].contact == 0) {
    b.l.at.z -= 0.01;
    b.step();
  }
  const double zc = b.l.at.z;
  while (fixate && b.l.at.z > zc - 8) {
    b.l.at.z -= 0.01;
    b.step();
  }
  auto go = [&](Vec3 to, double mm_per_step) { move(b, b.r, to, mm_per_step); };
  if (grasp.from_beyond) {  // round the overhang at 40 mm/s: down beyond it, in under it
    go({at.x, 190.0 + kSheetDyMm, kTableMm - grasp.under_mm}, 0.04);
    go({at.x, at.y, kTableMm - grasp.under_mm}, 0.04);
  }
  // The index pad up under the overhang at 10 mm/s; the thumb closes in 0.4 s.
  go({at.x, at.y, kTableMm - 1.2}, 0.01);
  b.hold(0.1);
  for (int i = 1; i <= 500; ++i) {
    b.r.q[THJ5] = grasp.open_thj5 + (kCloseThj5 - grasp.open_thj5) * std::min(1.0, i / 400.0);
    b.step();
  }
  Fold out;
  out.pinch_n = b.hand(Side::right).tip[0].normal_force_n;
  const int node = nearest_node(*b.world, {at.x, at.y, kTableMm});
  const Vec3 rel0 = b.world->sheet().positions()[node] - pad(b.hand(Side::right), 0);
  const double near0 = near_edge_y(*b.world);
  // The fold: 6 s, the pinch about the crease line.
  const KDL::Rotation palm0 = b.r.palm;
  const double yc = kSheetDyMm, r0 = at.y - yc, z0 = b.r.at.z;
  const int n = 6000;
  for (int i = 1; i <= n; ++i) {
    const double th = std::numbers::pi * i / n;
    const double r = r0 * (1.0 - 0.15 * std::sin(th));
    b.r.at = {at.x, yc + r * std::cos(th), z0 + r * std::sin(th)};
    b.r.palm = KDL::Rotation::RotX(std::min(deg(120), th)) * palm0;
    b.step();
    const Vec3 rel = b.world->sheet().positions()[node] - pad(b.hand(Side::right), 0);
    out.worst_slip_mm = std::max(out.worst_slip_mm, sheet::norm(rel - rel0));
    for (const auto& t : b.hand(Side::right).tip) out.peak_n = std::max(out.peak_n, double(t.normal_force_n));
    if (i % 50 == 0) out.worst_stretch = std::max(out.worst_stretch, max_edge_stretch(*b.world));
  }
  b.hold(0.5);
  out.near_drag_mm = std::fabs(near_edge_y(*b.world) - near0);
  // The left index slides out from under the top layer at 45 mm/s, off the sheet's left edge.
  const Vec3 l0 = b.l.at;
  for (int i = 1; i <= 2000; ++i) {
    b.l.at = l0 + Vec3{-90.0 * i / 2000.0, 0, 0};
    b.step();
  }
  out.edges_apart_mm = edges_apart(*b.world);
  out.on_top = on_top(*b.world);
  REQUIRE(b.world->state().rollbacks == 0);
  return out;
}

void print(const std::string& tag, const Fold& f) {
  MESSAGE(tag << ": pinch " << f.pinch_n << " N (peak " << f.peak_n << " N), worst slip " << f.worst_slip_mm
              << " mm, near edge dragged " << f.near_drag_mm << " mm; far edge " << f.edges_apart_mm << " mm from the near edge, "
              << 100.0 * f.on_top << " % of the far half on top of the near half"
              << (f.worst_stretch > 0 ? "; largest edge stretch over the fold " + std::to_string(100.0 * f.worst_stretch) + " %"
                                      : std::string()));
}

// Folded: the far edge over the near one within 25 mm (a dropped sheet: ~290 mm), the far half
// on top of the near half.
bool folded(const Fold& f) { return f.edges_apart_mm < 25.0 && f.on_top > 0.9; }

}  // namespace

TEST_CASE("the hands fold the sheet in half: one pinches the far edge and lays it over the near one, the other fixates") {
  Bimanual b;
  const Fold f = fold(nominal(), b);
  print("fold", f);
  CHECK(folded(f));
  CHECK(f.worst_slip_mm < 18.0);  // held: less than the pads' length
  CHECK(f.near_drag_mm < 10.0);   // fixated
  CHECK(f.peak_n < 10.0);         // what the taxels read: the squeeze, no step of tens of N

  WorldParams slippery = nominal();
  slippery.finger_friction = false;
  Bimanual b0;
  const Fold lost = fold(slippery, b0);
  print("frictionless fingers", lost);
  CHECK_FALSE(folded(lost));

  Bimanual b1;
  const Fold loose = fold(nominal(), b1, false);
  print("no fixation", loose);
  CHECK_FALSE(f.near_drag_mm >= 10.0);
  CHECK(loose.near_drag_mm >= 10.0);  // the pinch drags the unheld sheet after it
  // (Where its far edge then lands, 29-55 mm from the near edge over the arithmetic's variants,
  // is too near "folded" to tell.)
}

TEST_CASE("the hand pinches the drooping far edge from beyond it, round the overhang, and folds; straight in at the pinch's height it pushes the edge away") {
  // As config/folds/half.yaml's grasp: down beyond the edge to 35 mm under the table top, in, up.
  Bimanual b;
  const Fold f = fold(nominal(), b, true, from_beyond(35.0));
  print("from beyond, round the overhang", f);
  CHECK(f.pinch_n > 0.1);
  CHECK(folded(f));
  CHECK(f.near_drag_mm < 10.0);
  // Failing variant: in at 8 mm under the table top, where the drooping edge hangs.
  Bimanual b0;
  const Fold high = fold(nominal(), b0, true, from_beyond(8.0));
  print("from beyond, in at 8 mm", high);
  CHECK_FALSE(folded(high));
}
