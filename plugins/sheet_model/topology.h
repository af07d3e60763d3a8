// Grid geometry and link topology of the sheet (built once, at configure time).
#pragma once

#include <cstdint>
#include <vector>

#include "sheet_params.h"

namespace crease::sheet {

enum class LinkKind : std::uint8_t { structural, bending };

// The regular grid: node (i, j) sits at u = i*du, v = j*dv, index j*W + i.
struct Grid {
  int w = 0, h = 0;     // nodes along u, v
  double du = 0, dv = 0;  // node spacing, mm
  double width_mm = 0, height_mm = 0;

  [[nodiscard]] int count() const { return w * h; }
  [[nodiscard]] int index(int i, int j) const { return j * w + i; }
  [[nodiscard]] Vec2 sheet_of(int node) const { return {(node % w) * du, (node / w) * dv}; }
};

// Links stored structure-of-arrays; triangles (for normals and self-collision) as triples.
struct Topology {
  Grid grid;
  std::vector<std::int32_t> a, b;  // link end nodes
  std::vector<LinkKind> kind;
  std::vector<std::int32_t> tri;   // 3 node indices per triangle, 2 per grid cell
  int structural_count = 0;
  int bending_count = 0;

  [[nodiscard]] int link_count() const { return static_cast<int>(a.size()); }
  [[nodiscard]] int triangle_count() const { return static_cast<int>(tri.size() / 3); }
};

// Builds the grid and links. Throws crease::ConfigError naming the bad parameter.
[[nodiscard]] Topology build_topology(const GridParams& grid, const TopologyParams& topo);

}  // namespace crease::sheet
