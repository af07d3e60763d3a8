// Sheet coordinates of the key-points of a regular marker layout (seed 000 IV.A: each marker
// gives five key-points, its centre and four corners), for tests, benchmarks and the
// simulated world. Default: 5 x 7 markers of 20 mm on A4 (35 markers, 175 key-points).
#pragma once

#include <vector>

#include "vec3.h"

namespace crease::sheet {

// A regular grid of square markers, centred in equal cells of the sheet: only what the
// key-points' sheet positions need. The printed layout the cameras detect (ids, faces, the
// dictionary, a layout file) is vision::MarkerLayout (plugins/camera_rig/marker_layout.h).
struct SyntheticMarkerGrid {
  int cols = 5, rows = 7;
  double width_mm = 210, height_mm = 297;
  double marker_mm = 20;
};

// Key-point sheet positions, marker by marker: centre, then the four corners.
[[nodiscard]] inline std::vector<Vec2> marker_keypoints(const SyntheticMarkerGrid& m) {
  std::vector<Vec2> out;
  const double h = 0.5 * m.marker_mm;
  for (int r = 0; r < m.rows; ++r) {
    for (int c = 0; c < m.cols; ++c) {
      const Vec2 o{(c + 0.5) * m.width_mm / m.cols, (r + 0.5) * m.height_mm / m.rows};
      out.push_back(o);
      out.push_back({o.u - h, o.v - h});
      out.push_back({o.u + h, o.v - h});
      out.push_back({o.u + h, o.v + h});
      out.push_back({o.u - h, o.v + h});
    }
  }
  return out;
}

}  // namespace crease::sheet
