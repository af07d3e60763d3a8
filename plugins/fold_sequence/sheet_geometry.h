// What the sequence reads of the tracked sheet (sheet_state, the model's estimate, never the
// world's truth): the sheet frame arm_motion resolves sheet-frame goals in (origin node (0, 0),
// x along u, z = x cross (node (0, (H-1)/4) - origin), y = z x x;
// plugins/arm_motion/sheet_frame.h), a node's world position by its sheet coordinates, and the
// crease nearest to a line. World mm. RT: reads a few nodes.
#pragma once

#include "core/port_types/sheet_state.h"

namespace crease::fold {

struct SheetFrame {
  double origin[3];
  double x[3], y[3], z[3];  // unit axes in the world
};

// False for a state with fewer than 2 x 2 nodes, non-finite corners or degenerate edges.
[[nodiscard]] bool sheet_frame(const SheetState& s, SheetFrame& f) noexcept;
// The world position of sheet-frame point P (u, v, -h: a fold file's point) in frame F.
void sheet_to_world(const SheetFrame& f, const double p[3], double out[3]) noexcept;
// World pose (P mm, quaternion Q [x y z w]) into frame F's coordinates (P_OUT, Q_OUT): the
// inverse of sheet_to_world for a point, and for an orientation its turn seen from F.
void world_to_sheet(const SheetFrame& f, const double p[3], const double q[4], double p_out[3],
                    double q_out[4]) noexcept;
// Sheet-frame pose (P mm, Q) of frame F into the world: sheet_to_world for the point, and the
// orientation turned by F's rotation (the inverse of world_to_sheet).
void sheet_to_world(const SheetFrame& f, const double p[3], const double q[4], double p_out[3],
                    double q_out[4]) noexcept;
// The heading of F's x axis (u) about the world's vertical: atan2(x_y, x_x), rad.
[[nodiscard]] double frame_yaw(const SheetFrame& f) noexcept;
// Sheet-frame orientation Q turned by ALPHA rad about the world's vertical, again in F's
// coordinates.
void turn_about_vertical(const SheetFrame& f, double alpha_rad, const double q[4],
                         double q_out[4]) noexcept;
// The world position of the node nearest to sheet coordinates (u, v) mm. False as above.
[[nodiscard]] bool node_at(const SheetState& s, double u, double v, double out[3]) noexcept;
// How far sheet point (U, V) lies beyond the line A-B (sheet mm), positive on the side SIDE lies
// on, mm. NaN for a degenerate line.
[[nodiscard]] double beyond_line(const double a[2], const double b[2], const double side[2],
                                 double u, double v) noexcept;
// The sheet point (u, v) mm of the tracked sheet's part beyond the line A-B (sheet mm; the side
// SIDE lies on) that lies under world point P: the node of that part nearest to P in x, y (nodes
// within 1 mm of the line left out), within MAX_MM, refined by one linear step of its grid
// neighbours (at most one cell). What a finger pressing a laid flap holds. False when none.
[[nodiscard]] bool part_point_under(const SheetState& s, const double a[2], const double b[2],
                                    const double side[2], const double p[3], double max_mm,
                                    double uv[2]) noexcept;
// The crease of s nearest to the segment a-b (sheet mm, by the sum of its end points'
// distances, either direction), into a, b (oriented like the given one). False when s has none.
[[nodiscard]] bool nearest_crease(const SheetState& s, double a[2], double b[2]) noexcept;

}  // namespace crease::fold
