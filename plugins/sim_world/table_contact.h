// A robot shape against the table: a slab whose top is at z = top_mm over the extent
// {x_min, x_max, y_min, y_max} (an extent of +-WorldParams::kNoEdge: no edge that way).
// A shape whose lowest point lies over the extent and under the top is pushed out through the
// nearest face: the top (up), or a finite side face when the shape is less deep past that face
// than under the top (a finger that came in under the top from beyond an edge meets the edge's
// face, sideways: taken as under the top, 35 mm deep, it read 1-5 kN in the folding trials).
// Over the extent and above the top: the gap to the top (a negative depth). RT: arithmetic.
#pragma once

#include "plugins/sim_world/shape_geometry.h"

namespace crease::world {

// Whether P lies over the table top's extent in x and y.
[[nodiscard]] inline bool over_extent(Vec3 p, const double extent[4]) noexcept {
  return p.x >= extent[0] && p.x <= extent[1] && p.y >= extent[2] && p.y <= extent[3];
}

struct TableContact {
  bool over = false;    // the shape's lowest point lies over the extent (else no contact at all)
  double depth_mm = 0;  // how far the shape is in, along `normal`; negative: the gap to the top
  Vec3 point;           // the shape's point deepest in, world mm
  Vec3
      normal;  // from the shape into the table: (0, 0, -1) at the top, outward's opposite at a side
};

[[nodiscard]] inline TableContact table_contact(const Geom& g, const Pose& pose, double top_mm,
                                                const double extent[4]) noexcept {
  TableContact c;
  const Vec3 low = lowest_point(g, pose);
  c.over = over_extent(low, extent);
  if (!c.over) return c;
  c.depth_mm = top_mm - low.z;
  c.point = low;
  c.normal = Vec3{0, 0, -1};
  if (c.depth_mm <= 0) return c;
  const Vec3 m = pose.t;
  const double hx = half_extent(g, pose, 0), hy = half_extent(g, pose, 1);
  // Each side face: how far the shape reaches past it into the slab (an infinite extent: never
  // the nearest), its deepest point and the normal into the table.
  const struct {
    double depth;
    Vec3 point, normal;
  } side[4] = {
      {(m.x + hx) - extent[0], {m.x + hx, m.y, m.z}, {1, 0, 0}},   // x_min face
      {extent[1] - (m.x - hx), {m.x - hx, m.y, m.z}, {-1, 0, 0}},  // x_max face
      {(m.y + hy) - extent[2], {m.x, m.y + hy, m.z}, {0, 1, 0}},   // y_min face
      {extent[3] - (m.y - hy), {m.x, m.y - hy, m.z}, {0, -1, 0}},  // y_max face
  };
  for (const auto& s : side)
    if (s.depth < c.depth_mm) {
      c.depth_mm = s.depth;
      c.point = s.point;
      c.normal = s.normal;
    }
  return c;
}

}  // namespace crease::world
