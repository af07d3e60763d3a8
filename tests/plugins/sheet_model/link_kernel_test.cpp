// One pass of the link kernel (seed 001 Eqs. 2-3) on hand-computed cases.
#include "plugins/sheet_model/link_kernel.h"

#include <doctest/doctest.h>

using namespace crease::sheet;

TEST_CASE("a link moves its ends along it by their weights") {
  PackedLinks l;
  l.a = {0};
  l.b = {1};
  l.rest = {1.0};
  l.wa = {0.25};  // e.g. w_a = 1, w_b = 3, alpha = 0: w_a / (w_a + w_b)
  l.wb = {0.75};
  double x[6] = {0, 0, 0, 3, 0, 0};  // stretched by 2
  project_links_rt(l, x);
  CHECK(x[0] == doctest::Approx(0.5));  // moves w_a/(w_a+w_b) * 2
  CHECK(x[3] == doctest::Approx(1.5));
  CHECK(x[3] - x[0] == doctest::Approx(1.0));
}

TEST_CASE("coincident ends are left alone (no division by zero)") {
  PackedLinks l;
  l.a = {0};
  l.b = {1};
  l.rest = {1.0};
  l.wa = {0.5};
  l.wb = {0.5};
  double x[6] = {1, 2, 3, 1, 2, 3};
  project_links_rt(l, x);
  CHECK(x[0] == 1.0);
  CHECK(x[3] == 1.0);
  CHECK(x[5] == 3.0);
}
