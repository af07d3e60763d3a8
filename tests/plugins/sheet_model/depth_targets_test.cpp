// The sheet model's depth targets (SheetModel::set_normal_targets, XPBD backend; the runner's
// set_depth_targets): a target pulls its sheet point along the model's normal only, so targets
// displaced both off the surface and along it move a flat sheet off the table and not along
// it; with depth_along_normal off (3-D springs) the same targets drag it along too. Stale
// targets are dropped.
#include "core/port_types/depth_targets.h"

#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "plugins/sheet_model/sheet_runner.h"
#include "plugins/sim_world/scene/fold_script.h"

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

// depth_hold_hidden_mm: paper under a layer, which no depth target pulls, keeps its place on the
// table; paper hidden only by something else (a hand over it) follows the sheet.
namespace {

// The runner's depth targets from POS (world mm) for the nodes SEL picks (3-D springs).
void targets_at(const SheetParams& p, std::span<const Vec3> pos,
                const std::function<bool(int, int)>& sel, Vec3 shift, std::int64_t now_ns,
                crease::DepthTargets& t) {
  const int W = p.grid.nodes_u, H = p.grid.nodes_v;
  t.count = 0;
  t.timestamp_ns = now_ns;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      if (!sel(i, j)) continue;
      auto& q = t.points[t.count++];
      const Vec3 x = pos[static_cast<std::size_t>(j * W + i)] + shift;
      q.world_mm[0] = float(x.x);
      q.world_mm[1] = float(x.y);
      q.world_mm[2] = float(x.z);
      q.sheet_mm[0] = float(i * p.grid.width_mm / (W - 1));
      q.sheet_mm[1] = float(j * p.grid.height_mm / (H - 1));
      q.weight = 1.0f;
    }
}

// A sheet model on the table at z = 0 with 3-D depth springs and the hold at HOLD_MM.
struct HoldRig {
  SheetParams p;
  SheetRunner r;
  std::unique_ptr<crease::SheetState> st = std::make_unique<crease::SheetState>();
  std::unique_ptr<crease::DepthTargets> t = std::make_unique<crease::DepthTargets>();
  int W = 0, H = 0;
  static SheetParams params(double hold_mm) {
    SheetParams p;
    p.solver.depth_along_normal = false;
    p.solver.depth_hold_hidden_mm = hold_mm;
    return p;
  }
  explicit HoldRig(double hold_mm)
      : p(params(hold_mm)), r(p, 0.0), W(p.grid.nodes_u), H(p.grid.nodes_v) {}
};

// The half fold's flap (v < h/2) led over by targets (the fold script, 5 s to 175 deg, held 3 s),
// then dragged 15 mm along +x in 1 s: how far the lower layer's far rows (under the flap, no
// target) move along x in that second (mm, mean).
double lower_layer_drag(double hold_mm) {
  HoldRig rig(hold_mm);
  auto& [p, r, st, t, W, H] = rig;
  const auto script = FoldScript::half_fold(p.grid);
  std::vector<Vec3> pos(static_cast<std::size_t>(W * H));
  crease::SheetCreaseEvent crease;
  crease.a_mm[1] = crease.b_mm[1] = float(0.5 * p.grid.height_mm);
  crease.b_mm[0] = float(p.grid.width_mm);
  r.apply(crease);
  const auto flap = [H](int, int j) { return j < H / 2; };
  std::int64_t now = 1'000'000'000;
  for (int k = 0; k < 8 * 60; ++k, now += 16'666'667) {
    script.node_positions(k / 60.0, pos);
    targets_at(p, pos, flap, {}, now, *t);
    r.set_depth_targets(*t);
    (void)r.step_rt(1.0 / 60, now, *st);
  }
  const auto far_rows_x = [&] {
    double x = 0;
    int n = 0;
    for (int j = H - 6; j < H; ++j)
      for (int i = 0; i < W; ++i, ++n)
        x += r.model().positions()[static_cast<std::size_t>(j * W + i)].x;
    return x / n;
  };
  const double before = far_rows_x();
  for (int k = 0; k < 60; ++k, now += 16'666'667) {
    targets_at(p, pos, flap, {15.0 * (k + 1) / 60.0, 0, 0}, now, *t);
    r.set_depth_targets(*t);
    (void)r.step_rt(1.0 / 60, now, *st);
  }
  return far_rows_x() - before;
}

// A flat sheet on the table, targets on every node but a 3 x 3 patch (a hand over it), all moved
// 15 mm along +x in 1 s: how far the patch moves along x (mm, mean).
double hand_hidden_patch_drag(double hold_mm) {
  HoldRig rig(hold_mm);
  auto& [p, r, st, t, W, H] = rig;
  const std::vector<Vec3> flat(r.model().positions().begin(), r.model().positions().end());
  const auto in_patch = [W, H](int i, int j) {
    return std::abs(i - W / 2) <= 1 && std::abs(j - H / 2) <= 1;
  };
  std::int64_t now = 1'000'000'000;
  for (int k = 0; k < 60; ++k, now += 16'666'667) {
    targets_at(
        p, flat, [&](int i, int j) { return !in_patch(i, j); }, {15.0 * (k + 1) / 60.0, 0, 0}, now,
        *t);
    r.set_depth_targets(*t);
    (void)r.step_rt(1.0 / 60, now, *st);
  }
  double dx = 0;
  int n = 0;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i)
      if (in_patch(i, j)) {
        const auto k = static_cast<std::size_t>(j * W + i);
        dx += r.model().positions()[k].x - flat[k].x;
        ++n;
      }
  return dx / n;
}

}  // namespace

TEST_CASE(
    "paper under a laid flap keeps its place while the flap is dragged; paper under a hand "
    "follows") {
  const double held = lower_layer_drag(1.5), free = lower_layer_drag(0.0);
  const double patch_held = hand_hidden_patch_drag(1.5), patch_free = hand_hidden_patch_drag(0.0);
  MESSAGE("the lower layer under the flap dragged 15 mm: "
          << held << " mm held, " << free << " mm without the hold; a patch under a hand: "
          << patch_held << " and " << patch_free << " mm");
  CHECK(std::abs(held) < 1.0);
  CHECK(free > 3.0);  // the failing variant: the links drag the hidden layer along
  CHECK(patch_held > 10.0);
  CHECK(patch_free == doctest::Approx(patch_held).epsilon(0.05));
}
