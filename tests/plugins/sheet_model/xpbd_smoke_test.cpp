// Every path of the XPBD step in under a simulated second (also run under ASan+UBSan):
// table and sphere contacts, self-collision, creases added and removed, memorize,
// plasticity, key-points and targets, pins, reset.
#include "plugins/sheet_model/xpbd_sheet.h"

#include <doctest/doctest.h>

#include <vector>

#include "plugins/sheet_model/collision_world.h"
#include "plugins/sheet_model/fold_script.h"
#include "plugins/sheet_model/keypoint_predictor.h"
#include "plugins/sheet_model/synthetic_markers.h"

using namespace crease::sheet;

TEST_CASE("a short folded run touches every path and stays finite") {
  SheetParams p;
  p.grid.nodes_u = 8;
  p.grid.nodes_v = 11;
  p.solver.substeps = 4;
  p.solver.plasticity_rate = 0.3;
  p.solver.yield_strain = 0.002;
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
  const auto kps = marker_keypoints(MarkerLayout{});
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
