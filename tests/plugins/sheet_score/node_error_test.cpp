#include "plugins/sheet_score/node_error.h"

#include <doctest/doctest.h>

#include <memory>

using crease::SheetState;

namespace {
std::unique_ptr<SheetState> grid(int nu, int nv, float dz) {
  auto s = std::make_unique<SheetState>();
  s->nodes_u = static_cast<decltype(s->nodes_u)>(nu);
  s->nodes_v = static_cast<decltype(s->nodes_v)>(nv);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      float* p = s->position_mm[j * nu + i];
      p[0] = 10.0f * static_cast<float>(i);
      p[1] = 10.0f * static_cast<float>(j);
      p[2] = dz;
    }
  return s;
}
}  // namespace

TEST_CASE("the mean node distance of a sheet lifted by 3 mm is 3 mm; other grids cannot be compared") {
  const auto truth = grid(4, 5, 0.0f);
  const auto lifted = grid(4, 5, 3.0f);
  CHECK(crease::sheet_score::mean_node_distance_mm(*lifted, *truth) == doctest::Approx(3.0));
  CHECK(crease::sheet_score::mean_node_distance_mm(*truth, *truth) == 0.0);
  lifted->position_mm[0][0] += 20.0f;  // one node of 20 moved 20 mm sideways: 3 -> (19*3 + sqrt(409)) / 20
  CHECK(crease::sheet_score::mean_node_distance_mm(*lifted, *truth) == doctest::Approx((19 * 3.0 + std::sqrt(409.0)) / 20));
  CHECK(crease::sheet_score::mean_node_distance_mm(*grid(5, 4, 0.0f), *truth) < 0);
  CHECK(crease::sheet_score::mean_node_distance_mm(*grid(0, 0, 0.0f), *grid(0, 0, 0.0f)) < 0);  // no sheet
}
