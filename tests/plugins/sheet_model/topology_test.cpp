#include "plugins/sheet_model/topology.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <set>
#include <utility>

#include "core/errors.h"

using namespace crease::sheet;

TEST_CASE("seed 000 topology gives exactly 8722 links on the default A4 sheet") {
  const Topology t = build_topology(GridParams{}, TopologyParams{});
  MESSAGE("links=" << t.link_count() << " structural=" << t.structural_count
                   << " bending=" << t.bending_count);
  CHECK(t.structural_count == 874);  // 294 horizontal + 300 vertical + 280 diagonals
  CHECK(t.bending_count == 7848);
  CHECK(t.link_count() == 8722);
  CHECK(t.triangle_count() == 2 * 14 * 20);
}

TEST_CASE("links are unique unordered pairs of distinct nodes") {
  const Topology t = build_topology(GridParams{}, TopologyParams{});
  std::set<std::pair<int, int>> seen;
  for (int k = 0; k < t.link_count(); ++k) {
    REQUIRE(t.a[k] != t.b[k]);
    const auto p = std::minmax(t.a[k], t.b[k]);
    CHECK(seen.insert({p.first, p.second}).second);
  }
}

TEST_CASE("the neighbourhood is configurable") {
  TopologyParams p;
  p.bend_min_city = 2;
  p.bend_max_city = 4;
  p.diagonals = Diagonals::none;
  const Topology t = build_topology(GridParams{}, p);
  CHECK(t.structural_count == 294 + 300);
  // city-block 2..4 in the 9x9 box on 15x21: counted independently here.
  int expect = 0;
  for (int dj = 0; dj <= 4; ++dj)
    for (int di = -4; di <= 4; ++di) {
      if (dj == 0 && di <= 0) continue;
      const int c = (di < 0 ? -di : di) + dj;
      if (c < 2 || c > 4) continue;
      expect += (15 - (di < 0 ? -di : di)) * (21 - dj);
    }
  CHECK(t.bending_count == expect);
}

TEST_CASE("bad parameters name the key") {
  GridParams g;
  g.nodes_u = 1;
  CHECK_THROWS_WITH_AS((void)build_topology(g, TopologyParams{}), doctest::Contains("grid.nodes_u"),
                       crease::ConfigError);
}
