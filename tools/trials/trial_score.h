// A folding trial's score from the world's truth (sim_world's `sheet_truth`), never from the
// tracked model: how far the fold the world's sheet shows is from the one the sequence file
// intends. Sheet coordinates (u, v) mm on the printed face, world mm (z up, the table at 0).
//
// The sheet's halves about the intended fold line: the base (the side the flap corner is not
// on) and the flap (the side of the sequence's corner, shift.corner_mm), each without a margin
// of kMarginMm about the line. The base is fitted as a rigid motion of the plane (u, v) ->
// world (x, y) (least squares over its nodes); a flap node folded flat onto it lies, seen
// through that motion, at the mirror image of its (u, v) about the fold line that was made.
//   fold_line_mm, fold_angle_deg: that line, fitted from the flap nodes lying on the base
//     (below kOnBaseMm and not kBelowTableMm under the table top, which a node hanging over the
//     table's edge is, and at least kFoldedMm from where they would lie unfolded), against the
//     intended one: its distance from the intended line's midpoint and the angle between them;
//     NaN when fewer than half the flap's nodes lie folded on the base (no fold was made);
//   corners_mm: the worst distance of the flap's sheet corners from where the intended fold puts
//     them (their mirror image on the base's plane);
//   retained_deg: the angle between the sheet's mean normals either side of the intended line
//     (kRetainedNearMm .. kRetainedFarMm from it): 0 flat, 180 folded flat;
//   max_stretch: the largest relative stretch of an edge of the truth grid (its rest length the
//     grid spacing): torn above kTornStretch; stretch_at_mm: that edge's midpoint (u, v);
//   off_table: kOffTableFraction of the nodes or more lie over kBelowTableMm below the table
//     top (pushed over an edge; a corner hanging over one, as the shift leaves it for the pinch,
//     is not);
//   slip_mm: the base's largest displacement from a reference state (the runner's choice).
// Pure functions, non-RT.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "core/port_types/sheet_state.h"

namespace crease::trials {

inline constexpr double kMarginMm = 15.0;
inline constexpr double kOnBaseMm = 5.0;
inline constexpr double kFoldedMm = 10.0;
inline constexpr double kRetainedNearMm = 15.0;
inline constexpr double kRetainedFarMm = 60.0;
inline constexpr double kTornStretch = 0.05;
inline constexpr double kBelowTableMm = 2.0;
inline constexpr double kOffTableFraction = 0.25;

// What the fold intends (from its sequence file).
struct FoldTarget {
  double line_mm[2][2] = {};  // (u0, v0), (u1, v1)
  double flap_corner_mm[2] = {};  // a point of the flap side (the corner the sequence moves)
};

// The success bounds.
struct Bounds {
  double fold_line_mm = 3.0;
  double fold_angle_deg = 2.0;
  double corners_mm = 5.0;
  double retained_deg = 150.0;
};

struct Score {
  double fold_line_mm = 0;    // NaN: no fold
  double fold_angle_deg = 0;  // NaN: no fold
  double corners_mm = 0;
  double retained_deg = 0;
  double max_stretch = 0;
  double stretch_at_mm[2] = {0, 0};  // (u, v) of the most stretched edge's midpoint
  double slip_mm = 0;         // NaN without a reference
  int flap_nodes = 0, folded_nodes = 0, base_nodes = 0;
  bool torn = false;
  bool off_table = false;
  bool valid = false;          // a sheet with a base to fit (else everything NaN)
  // Whether the sheet's figures meet the bounds, and the first that misses ("" when all do).
  bool shape_ok = false;
  std::string miss;
};

// A 2D rigid motion (u, v) -> (x, y): x = R p + t.
struct PlaneMotion {
  double c = 1, s = 0, tx = 0, ty = 0;
  [[nodiscard]] std::array<double, 2> apply(double u, double v) const noexcept {
    return {c * u - s * v + tx, s * u + c * v + ty};
  }
  [[nodiscard]] std::array<double, 2> invert(double x, double y) const noexcept {
    const double dx = x - tx, dy = y - ty;
    return {c * dx + s * dy, -s * dx + c * dy};
  }
};

// The sheet's node (i, j) in sheet coordinates (mm).
[[nodiscard]] std::array<double, 2> node_uv(const SheetState& s, int i, int j) noexcept;

// The base's rigid motion, fitted to its nodes (false: fewer than three).
bool fit_base(const SheetState& s, const FoldTarget& t, PlaneMotion& out, int* nodes = nullptr);

// The largest relative stretch of an edge of SHEET's grid (its rest length the grid spacing).
[[nodiscard]] double max_stretch(const SheetState& sheet, double* at_uv_mm = nullptr);

// The score of SHEET (the world's truth at the end), REFERENCE (the truth the slip is measured
// from; null: slip NaN).
[[nodiscard]] Score score_sheet(const SheetState& sheet, const FoldTarget& target, const Bounds& bounds,
                                const SheetState* reference = nullptr);

}  // namespace crease::trials
