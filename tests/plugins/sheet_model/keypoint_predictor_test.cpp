// Key-point prediction: constant velocity between observations, bounded by what the sheet
// allows for the unseen (never further from a seen key-point than on the sheet), and no
// prediction soon after a key-point was last seen.
#include "plugins/sheet_model/keypoint_predictor.h"

#include <doctest/doctest.h>

#include <vector>

using namespace crease::sheet;

namespace {

// Key-point 0 at sheet (0, 0), key-point 1 at sheet (100, 0): 100 mm apart on the sheet.
// Both seen at t = 0 and 0.1 s, key-point 1 moving at 500 mm/s along +x; then only 0 is seen.
std::vector<TargetPoint> run(const PredictorParams& p, double t_predict) {
  KeypointPredictor k(2, p);
  k.observe(0, {0, 0}, {0, 0, 0}, 0.0);
  k.observe(1, {100, 0}, {100, 0, 0}, 0.0);
  k.observe(0, {0, 0}, {0, 0, 0}, 0.1);
  k.observe(1, {100, 0}, {100, 0, 50}, 0.1);  // lifted 50 mm: 111.8 mm away, more than the sheet allows
  k.observe(0, {0, 0}, {0, 0, 0}, 0.2);       // key-point 1 no longer seen
  std::vector<TargetPoint> out(2);
  out.resize(static_cast<std::size_t>(k.predict(t_predict, out)));
  return out;
}

}  // namespace

TEST_CASE("an unseen key-point is predicted within its sheet distance of the seen ones") {
  const auto bounded = run(PredictorParams{}, 0.25);
  REQUIRE(bounded.size() == 2);
  CHECK(norm(bounded[0].world_mm) == doctest::Approx(0.0));                 // the seen one stays
  CHECK(norm(bounded[1].world_mm - bounded[0].world_mm) <= 100.0 + 1.0 + 1e-9);  // sheet distance + slack
  CHECK(bounded[1].world_mm.z > 50.0);  // still moving on, as far as the sheet lets it
  PredictorParams unbounded;           // the failing variant
  unbounded.bound_by_sheet = false;
  const auto free = run(unbounded, 0.25);
  REQUIRE(free.size() == 2);
  CHECK(free[1].world_mm.z == doctest::Approx(50.0 + 0.15 * 500.0));  // constant velocity, 0.15 s on
  CHECK(norm(free[1].world_mm - free[0].world_mm) > 150.0);
}

TEST_CASE("a key-point is no longer predicted soon after it was last seen") {
  auto seen_later = [](const PredictorParams& p, double t_newest) {
    KeypointPredictor k(2, p);
    k.observe(0, {0, 0}, {0, 0, 0}, 0.0);
    k.observe(1, {100, 0}, {100, 0, 0}, 0.0);
    k.observe(0, {0, 0}, {0, 0, 0}, t_newest);  // key-point 1 left out since 0 s
    std::vector<TargetPoint> out(2);
    return k.predict(t_newest + 0.01, out);
  };
  CHECK(seen_later(PredictorParams{}, 0.19) == 2);
  CHECK(seen_later(PredictorParams{}, 0.21) == 1);  // left out of observations for 0.2 s
  PredictorParams before;
  before.max_extrapolate_s = 1.5;
  CHECK(seen_later(before, 1.4) == 2);
  // A key-point in the newest observation stays however late the next one is (a slow vision
  // frame drops nothing), extrapolated at most max_extrapolate_s.
  KeypointPredictor k(1, PredictorParams{});
  k.observe(0, {0, 0}, {0, 0, 0}, 0.0);
  k.observe(0, {0, 0}, {0, 0, 1}, 0.1);  // 10 mm/s up
  std::vector<TargetPoint> out(1);
  REQUIRE(k.predict(5.0, out) == 1);
  CHECK(out[0].world_mm.z == doctest::Approx(1.0 + 0.2 * 10.0));
}

TEST_CASE("the fastest speed seen is remembered for a while") {
  KeypointPredictor k(1, PredictorParams{});
  k.observe(0, {0, 0}, {0, 0, 0}, 0.0);
  k.observe(0, {0, 0}, {0, 0, 8}, 0.1);  // 80 mm/s
  CHECK(k.fastest_speed(0.5, 1.0) == doctest::Approx(80.0));
  CHECK(k.fastest_speed(1.2, 1.0) == 0.0);
}
