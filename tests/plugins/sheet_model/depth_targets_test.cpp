// The sheet model's depth targets (SheetModel::set_normal_targets, XPBD backend; the runner's
// set_depth_targets): a target pulls its sheet point along the model's normal only, so targets
// displaced both off the surface and along it move a flat sheet off the table and not along
// it; with depth_along_normal off (3-D springs) the same targets drag it along too. Stale
// targets are dropped.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>

#include "core/port_types/depth_targets.h"
#include "plugins/sheet_model/sheet_runner.h"

using namespace crease::sheet;

namespace {

// Targets 20 mm above every node and 15 mm along +x of it; the sheet after 1 s.
struct Moved {
  double up_mm = 0, along_mm = 0;
};
Moved pull(bool along_normal, std::int64_t target_age_ns = 0) {
  SheetParams p;
  p.solver.depth_along_normal = along_normal;
  p.solver.depth_tangential_weight = 0.0;  // the normal only
  p.solver.self_collision = false;
  SheetRunner r(p, -1e9);  // table far below: gravity only
  auto st = std::make_unique<crease::SheetState>();
  const auto flat = std::vector<Vec3>(r.model().positions().begin(), r.model().positions().end());
  auto t = std::make_unique<crease::DepthTargets>();
  const int W = p.grid.nodes_u, H = p.grid.nodes_v;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      auto& q = t->points[t->count++];
      const Vec3 x = flat[static_cast<std::size_t>(j * W + i)];
      q.world_mm[0] = float(x.x + 15.0);
      q.world_mm[1] = float(x.y);
      q.world_mm[2] = float(x.z + 20.0);
      q.sheet_mm[0] = float(i * p.grid.width_mm / (W - 1));
      q.sheet_mm[1] = float(j * p.grid.height_mm / (H - 1));
      q.weight = 1.0f;
    }
  const std::int64_t t0 = 5'000'000'000;
  t->timestamp_ns = t0 - target_age_ns;
  r.set_depth_targets(*t);
  for (int k = 0; k < 60; ++k) (void)r.step_rt(1.0 / 60, t0 + k * 16'666'667, *st);
  Moved m;
  for (std::size_t i = 0; i < flat.size(); ++i) {
    m.up_mm += (r.model().positions()[i].z - flat[i].z) / flat.size();
    m.along_mm += (r.model().positions()[i].x - flat[i].x) / flat.size();
  }
  return m;
}

}  // namespace

TEST_CASE("depth targets pull along the model's normal; 3-D springs drag the sheet along too") {
  const Moved n = pull(true);
  const Moved s = pull(false);
  MESSAGE("along the normal: up " << n.up_mm << " mm, along " << n.along_mm << " mm; 3-D: up " << s.up_mm
                                  << " mm, along " << s.along_mm << " mm");
  CHECK(n.up_mm == doctest::Approx(20.0).epsilon(0.1));
  CHECK(std::abs(n.along_mm) < 0.5);
  CHECK(s.up_mm == doctest::Approx(20.0).epsilon(0.1));
  CHECK(s.along_mm == doctest::Approx(15.0).epsilon(0.1));
}

TEST_CASE("depth targets older than the horizon are dropped: the sheet falls") {
  const Moved old = pull(true, static_cast<std::int64_t>((SheetRunner::kDepthMaxAgeS + 0.5) * 1e9));
  MESSAGE("stale targets: up " << old.up_mm << " mm");
  CHECK(old.up_mm < -100.0);  // a second of free fall: ~ -4.9 m with no table (damped and capped)
}

// Targets rising at 100 mm/s, one set every 0.2 s (a depth path at 5 Hz), the model at 60 Hz:
// with the prediction the model keeps up between sets; without it, it waits for the next set
// (half a set's rise behind on average).
double rising_lag(bool predict) {
  SheetParams p;
  p.solver.self_collision = false;
  SheetRunner r(p, -1e9);
  r.set_depth_prediction(predict);
  auto st = std::make_unique<crease::SheetState>();
  const auto flat = std::vector<Vec3>(r.model().positions().begin(), r.model().positions().end());
  auto t = std::make_unique<crease::DepthTargets>();
  const int W = p.grid.nodes_u, H = p.grid.nodes_v;
  constexpr double kSpeed = 100.0;  // mm/s
  const std::int64_t t0 = 5'000'000'000;
  double lag = 0;
  int samples = 0;
  for (int k = 0; k < 120; ++k) {  // 2 s at 60 Hz
    const std::int64_t now = t0 + k * 16'666'667;
    if (k % 12 == 0) {  // a new set every 0.2 s, of the sheet's height then
      t->count = 0;
      t->timestamp_ns = now;
      for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
          auto& q = t->points[t->count++];
          const Vec3 x = flat[static_cast<std::size_t>(j * W + i)];
          q.world_mm[0] = float(x.x);
          q.world_mm[1] = float(x.y);
          q.world_mm[2] = float(x.z + kSpeed * double(now - t0) * 1e-9);
          q.sheet_mm[0] = float(i * p.grid.width_mm / (W - 1));
          q.sheet_mm[1] = float(j * p.grid.height_mm / (H - 1));
          q.weight = 1.0f;
        }
      r.set_depth_targets(*t);
    }
    (void)r.step_rt(1.0 / 60, now, *st);
    if (k < 30) continue;  // after two sets: a velocity
    double z = 0;
    for (std::size_t i = 0; i < flat.size(); ++i) z += (r.model().positions()[i].z - flat[i].z) / flat.size();
    lag += kSpeed * double(now - t0) * 1e-9 - z;
    ++samples;
  }
  return lag / samples;
}

TEST_CASE("between depth sets a target moves on at its node's velocity; without the prediction the model lags") {
  const double with = rising_lag(true), without = rising_lag(false);
  MESSAGE("mean lag behind a sheet rising at 100 mm/s, sets at 5 Hz: " << with << " mm predicted, " << without
                                                                      << " mm held");
  CHECK(std::abs(with) < 2.0);
  CHECK(without > 7.0);  // ~ half of the 20 mm a set period rises
}
