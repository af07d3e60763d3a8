// A sheet as a triangle mesh of WxH world node positions (mm), the renderer's and the
// tests' ground truth. Node (i, j) sits at sheet (u, v) = (i*w/(W-1), j*h/(H-1)); nodes are
// stored row by row (j outer). Each grid cell is split into two triangles
// (i,j)(i+1,j)(i,j+1) and (i+1,j)(i+1,j+1)(i,j+1), both with positive (u, v) orientation.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/port_types/sheet_state.h"

namespace crease::vision {

struct SheetMesh {
  int nx = 0, ny = 0;           // nodes along u and v
  double w_mm = 0, h_mm = 0;    // sheet size
  std::vector<cv::Vec3d> nodes;  // world mm, size nx*ny, row by row
  std::int64_t timestamp_ns = -1;  // CLOCK_MONOTONIC time the geometry is of; -1: unknown

  [[nodiscard]] cv::Vec3d node(int i, int j) const { return nodes[static_cast<std::size_t>(j * nx + i)]; }
  [[nodiscard]] cv::Point2d node_uv(int i, int j) const {
    return {i * w_mm / (nx - 1), j * h_mm / (ny - 1)};
  }
  // World position of sheet point (u, v), interpolated on the triangle that contains it
  // (clamped to the sheet).
  [[nodiscard]] cv::Vec3d world_at(double u, double v) const;
  // Unit normal of the printed front face (pointing out of the paper) at (u, v).
  [[nodiscard]] cv::Vec3d front_normal_at(double u, double v) const;
};

// Flat sheet lying printed face up on the table, centred at `centre_mm`, rotated by
// `yaw_rad` about world z; u along world +x, v along world -y before the yaw.
SheetMesh flat_sheet(int nx, int ny, double w_mm, double h_mm, const cv::Vec3d& centre_mm,
                     double yaw_rad = 0.0);

// Rotates the part of the sheet with v > v_fold_mm about the world line through the fold
// (the mesh row at v_fold; it should be a node row) by angle_rad; positive lifts the flap
// towards the printed face (a valley fold seen from the front). 0 = flat, pi = folded flat.
SheetMesh fold_sheet(const SheetMesh& flat, double v_fold_mm, double angle_rad);

// The sheet of a SheetState (the `sheet_truth` port: the simulated world's sheet), stamped with
// its time. A state with fewer than 2 x 2 nodes (never written) gives an empty mesh (nx = ny =
// 0): the renderer then draws the table without a sheet.
SheetMesh mesh_of(const crease::SheetState& state);

}  // namespace crease::vision
