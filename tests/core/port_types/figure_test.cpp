// Figure::set_share over a run of calls, as the plugins that report a share of events call it
// (a camera's late frames, a tracker's dropped views): the mean over the run is the share of
// hits, the newest sample says whether the last call added one, the worst whether any came.
#include "core/port_types/figure.h"

#include <doctest/doctest.h>

#include <cstdint>

TEST_CASE(
    "a share of events: the run's mean is the share of hits, the newest sample follows each call") {
  crease::Figure f = crease::Figure::named("frames late", "%", "frames");
  std::uint64_t events = 0, hits = 0, seen = 0;
  // 10 calls of 4 events each; the 3rd and 7th add one hit each.
  for (int call = 1; call <= 10; ++call) {
    events += 4;
    if (call == 3 || call == 7) ++hits;
    f.set_share(events, hits, seen);
    CHECK(f.last == ((call == 3 || call == 7) ? 100.0 : 0.0));
    CHECK(f.max == (call >= 3 ? 100.0 : 0.0));
    seen = hits;
  }
  CHECK(f.count == 40);
  CHECK(f.mean() == doctest::Approx(5.0));  // 2 of 40
  // A call with nothing new keeps the figure's totals.
  f.set_share(events, hits, seen);
  CHECK(f.count == 40);
  CHECK(f.last == 0.0);
  CHECK(f.mean() == doctest::Approx(5.0));
}
