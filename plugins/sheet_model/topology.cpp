#include "topology.h"

#include <cstdlib>
#include <string>

#include "core/assert.h"

namespace crease::sheet {
namespace {

// Parameters come from a plugin's configuration (or a test's): bad input, ConfigError.
void require(bool ok, const char* key, const char* why) {
  if (!ok) throw crease::ConfigError(std::string("sheet_model: ") + key + ": " + why);
}

}  // namespace

Topology build_topology(const GridParams& gp, const TopologyParams& tp) {
  require(gp.nodes_u >= 2 && gp.nodes_u <= 64, "grid.nodes_u", "must be in [2, 64]");
  require(gp.nodes_v >= 2 && gp.nodes_v <= 64, "grid.nodes_v", "must be in [2, 64]");
  require(gp.width_mm > 0 && gp.height_mm > 0, "grid.width_mm/height_mm", "must be > 0");
  require(tp.bend_box_radius >= 0 && tp.bend_box_radius <= 8, "topology.bend_box_radius",
          "must be in [0, 8]");
  require(tp.bend_min_city >= 2, "topology.bend_min_city", "must be >= 2 (1 is structural)");

  Topology t;
  Grid& g = t.grid;
  g.w = gp.nodes_u;
  g.h = gp.nodes_v;
  g.width_mm = gp.width_mm;
  g.height_mm = gp.height_mm;
  g.du = gp.width_mm / (g.w - 1);
  g.dv = gp.height_mm / (g.h - 1);

  auto add = [&t](int p, int q, LinkKind k) {
    t.a.push_back(p);
    t.b.push_back(q);
    t.kind.push_back(k);
  };
  // Structural: as Bullet's CreatePatch with diagonals (ANCHORS.md), row by row.
  for (int j = 0; j < g.h; ++j) {
    for (int i = 0; i < g.w; ++i) {
      const int n = g.index(i, j);
      if (i + 1 < g.w) add(n, g.index(i + 1, j), LinkKind::structural);
      if (j + 1 < g.h) add(n, g.index(i, j + 1), LinkKind::structural);
      if (i + 1 < g.w && j + 1 < g.h) {
        const bool main_diag = ((i + j) & 1) != 0;
        if (tp.diagonals == Diagonals::both || (tp.diagonals == Diagonals::alternating && main_diag))
          add(n, g.index(i + 1, j + 1), LinkKind::structural);
        if (tp.diagonals == Diagonals::both || (tp.diagonals == Diagonals::alternating && !main_diag))
          add(g.index(i + 1, j), g.index(i, j + 1), LinkKind::structural);
        // Triangles split along the main diagonal when present, else along the other one.
        const int n00 = n, n10 = g.index(i + 1, j), n01 = g.index(i, j + 1), n11 = g.index(i + 1, j + 1);
        if (main_diag || tp.diagonals == Diagonals::none) {
          t.tri.insert(t.tri.end(), {n00, n10, n11, n00, n11, n01});
        } else {
          t.tri.insert(t.tri.end(), {n00, n10, n01, n10, n11, n01});
        }
      }
    }
  }
  t.structural_count = t.link_count();
  // Bending: every unordered pair in the box with city-block distance in [min, max].
  const int r = tp.bend_box_radius;
  for (int j = 0; j < g.h; ++j) {
    for (int i = 0; i < g.w; ++i) {
      for (int dj = 0; dj <= r; ++dj) {
        for (int di = -r; di <= r; ++di) {
          if (dj == 0 && di <= 0) continue;  // each unordered pair once
          const int city = std::abs(di) + dj;
          if (city < tp.bend_min_city || city > tp.bend_max_city) continue;
          const int i2 = i + di, j2 = j + dj;
          if (i2 < 0 || i2 >= g.w || j2 >= g.h) continue;
          add(g.index(i, j), g.index(i2, j2), LinkKind::bending);
        }
      }
    }
  }
  t.bending_count = t.link_count() - t.structural_count;
  return t;
}

}  // namespace crease::sheet
