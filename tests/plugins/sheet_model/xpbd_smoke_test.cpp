// Every path of the XPBD step in under a simulated second (also run under ASan+UBSan):
// table and sphere contacts, self-collision, creases added and removed, memorize,
// plasticity, key-points and targets, pins, reset.
#include "plugins/sheet_model/xpbd_sheet.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <vector>

#include "plugins/sheet_model/collision_world.h"
#include "plugins/sheet_model/keypoint_predictor.h"
#include "plugins/sheet_model/synthetic_markers.h"
#include "plugins/sim_world/scene/fold_script.h"

using namespace crease::sheet;

TEST_CASE("a short folded run touches every path and stays finite") {
  SheetParams p;
  p.grid.nodes_u = 8;
  p.grid.nodes_v = 11;
  p.solver.substeps = 4;
  p.solver.plasticity_rate = 0.3;
  p.solver.yield_strain = 0.002;
  p.solver.crease_strain = 0;  // the crease it folds about is given (below)
  CollisionWorld world;
  world.add_table(0.0);
  world.add_sphere(10.0, {60, 60, 5});
  world.add_box({20, 20, 10}, {150, 250, 0});
  world.add_capsule(5.0, 30.0, {100, 200, 0});
  XpbdSheet s(p);
  s.set_collision_world(&world);
  const int c = s.add_crease({{0, 148.5}, {210, 148.5}});
  REQUIRE(c >= 0);
  const FoldScript fold = FoldScript::half_fold(p.grid);
  std::vector<Vec3> x(s.node_count());
  fold.node_positions(4.9, x);  // ~170 deg: the flap lies over the lower half
  s.set_positions(x);
  const auto kps = marker_keypoints(SyntheticMarkerGrid{});
  KeypointPredictor pred(static_cast<int>(kps.size()));
  std::vector<TargetPoint> targets(kps.size());
  std::vector<KeypointObs> obs;
  s.pin(0, x[0]);
  for (int f = 0; f < 40; ++f) {
    const double t = 4.9 + f / 60.0;
    obs.clear();
    for (std::size_t k = 0; k < kps.size(); ++k) {
      pred.observe(static_cast<int>(k), kps[k], fold.position(kps[k], t), t);
      if (k % 3 == 0) obs.push_back({fold.position(kps[k], t), kps[k]});
    }
    s.set_targets(std::span<const TargetPoint>(targets.data(), pred.predict(t, targets)));
    s.set_keypoints(obs);
    if (f == 10) s.memorize_region({{0, 0}, {210, 100}});
    if (f == 20) CHECK(s.remove_crease(c));
    if (f == 30) s.memorize_all();
    s.step_rt(1.0 / 60);
    REQUIRE(s.state_finite());
  }
  CHECK(s.contact_stats().self_pairs > 0);      // the flap over the lower half
  CHECK(s.contact_stats().shape_contacts > 0);  // the lower half on the table
  std::vector<Vec3> n(s.node_count());
  std::vector<double> strain(s.link_count());
  s.compute_normals(n);
  s.compute_strains(strain);
  for (const Vec3& q : n) CHECK(norm(q) == doctest::Approx(1.0));
  s.reset_rt();
  CHECK(s.creases().count() == 0);
  CHECK(norm(s.positions()[0] - s.flat_position({0, 0})) == 0.0);
}

TEST_CASE("contact candidates are kept while the sheet rests and found again when needed") {
  SheetParams p;
  p.grid.nodes_u = 8;
  p.grid.nodes_v = 11;
  p.solver.substeps = 4;
  CollisionWorld world;
  world.add_table(0.0);
  const int ball = world.add_sphere(10.0, {400, 400, 50});  // far from the sheet
  XpbdSheet s(p);
  s.set_collision_world(&world);
  for (int f = 0; f < 60; ++f) s.step_rt(1.0 / 60);  // lies flat on the table
  const std::uint64_t resting = s.contact_detections();
  CHECK(resting >= 1);
  for (int f = 0; f < 30; ++f) s.step_rt(1.0 / 60);
  CHECK(s.contact_detections() == resting);  // nothing moved past the skin
  CHECK(s.contact_stats().shape_contacts == s.node_count());  // every node on the table
  world.set_pose(ball, {400, 400, 40});  // a moved shape: found again
  s.step_rt(1.0 / 60);
  CHECK(s.contact_detections() == resting + 1);
  const std::vector<Vec3> x(s.positions().begin(), s.positions().end());
  s.set_positions(x);  // a teleport: found again
  s.step_rt(1.0 / 60);
  CHECK(s.contact_detections() == resting + 2);
  // Lifting the sheet by more than the skin in one go (set_positions) drops the table.
  std::vector<Vec3> lifted = x;
  for (Vec3& q : lifted) q.z += 50.0;
  s.set_positions(lifted);
  s.step_rt(1.0 / 60);
  CHECK(s.contact_stats().shape_contacts == 0);
}

TEST_CASE("the AVX2 target and per-node passes agree with the scalar ones") {
  SheetParams p;
  p.grid.nodes_u = 8;
  p.grid.nodes_v = 11;
  p.solver.substeps = 4;
  p.solver.self_collision = false;
  XpbdSheet a(p), b(p);
  b.force_scalar_passes(true);
  const FoldScript fold = FoldScript::half_fold(p.grid);
  const auto kps = marker_keypoints(SyntheticMarkerGrid{});
  std::vector<TargetPoint> targets;
  for (const Vec2& k : kps) targets.push_back({fold.position(k, 2.0), k});
  a.set_targets(targets);
  b.set_targets(targets);
  a.pin(0, a.positions()[0]);  // a pinned node in the per-node passes
  b.pin(0, b.positions()[0]);
  for (int f = 0; f < 20; ++f) {
    a.step_rt(1.0 / 60);
    b.step_rt(1.0 / 60);
  }
  double diff = 0, moved = 0;
  for (int i = 0; i < a.node_count(); ++i) {
    diff = std::max(diff, norm(a.positions()[i] - b.positions()[i]));
    moved = std::max(moved, norm(a.positions()[i] - a.flat_position(a.grid().sheet_of(i))));
  }
  MESSAGE("largest difference " << diff << " mm; largest move " << moved << " mm");
  CHECK(moved > 10.0);  // the targets did pull the sheet
  CHECK(norm(a.positions()[0] - a.flat_position({0, 0})) == 0.0);
  CHECK(diff < 1e-6);
}
