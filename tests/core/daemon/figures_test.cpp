#include "core/daemon/figures.h"

#include <doctest/doctest.h>

#include "core/port.h"

using crease::Figure;

TEST_CASE("every Figure port is read, with its mean since the previous take, and printed by its own name") {
  crease::PortRegistry ports;
  auto* ch = ports.bind_latest_writer("tracking_error", crease::port_type_of<Figure>(), "score");
  (void)ports.bind_latest_writer("other", crease::PortType{"crease.test.Value", 1, 24}, "x");  // not a figure
  crease::daemon::FigureWatch watch(ports);
  CHECK(watch.take().empty());  // nothing written yet
  Figure f = Figure::named("tracking error", "mm", "frames");
  f.count = 4;
  f.sum = 8.0;  // 2 mm each
  f.last = 2.0;
  f.max = 3.0;
  ch->write(&f, 1);
  auto r = watch.take();
  REQUIRE(r.size() == 1);
  CHECK(r[0].port == "tracking_error");
  CHECK(r[0].window_count == 4);
  CHECK(r[0].window_mean == doctest::Approx(2.0));
  f.count = 6;
  f.sum = 20.0;  // two more samples of 6 mm
  ch->write(&f, 2);
  r = watch.take();
  CHECK(r[0].window_count == 2);
  CHECK(r[0].window_mean == doctest::Approx(6.0));
  CHECK(crease::daemon::progress_text(r) == "; tracking error: 6.00 mm (this second), 3.33 mm (mean so far)");
  CHECK(crease::daemon::summary_text(r) == "  tracking error: mean 3.33 mm over 6 frames, last 2.00 mm, worst 3.00 mm\n");
  r = watch.take();
  CHECK(r[0].window_count == 0);  // nothing new since: no figure for this second, not 0 mm
  CHECK(crease::daemon::progress_text(r) == "; tracking error: no frames (this second), 3.33 mm (mean so far)");
}
