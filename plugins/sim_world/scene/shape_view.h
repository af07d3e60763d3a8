// The world's robot as the simulated cameras see it: the arms' and hands' collision shapes of
// the `world_shapes` port (core/port_types/world_shapes.h) ray-cast exactly through a camera's
// distortion (the renderer's per-pixel rays), each within the pixels whose rays can meet its
// bounding box (the box clipped to the space in front of the camera), on a lattice of
// ShapeDrawing::lattice_px (interpolated between lattice points that meet it), depth-tested against
// the sheet the renderer drew (a finger under the sheet is hidden, one over it hides the sheet) and
// against the table's top (the table hides what is below it). Shapes as
// plugins/sim_world/shape_geometry.h (box edges rounded). Not RT code (a camera worker's).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "core/port_types/world_shapes.h"
#include "plugins/camera_rig/camera_model.h"
#include "plugins/sim_world/shape_geometry.h"

namespace crease::vision {

struct SceneShape {
  world::Geom geom;  // mm
  world::Pose pose;  // world mm
  crease::WorldShapes::Role role = crease::WorldShapes::Role::arm;  // what it is of (the port's)
  std::uint8_t side = 0;                                            // 0 right, 1 left
};

// The shapes of a `world_shapes` payload (its first `count`, at most kCapacity). OUT keeps its
// capacity: no allocation once it has held as many.
void shapes_of(const crease::WorldShapes& in, std::vector<SceneShape>& out);

// The first point where the ray c + s * d (world mm; s > s_min) enters the shape, and the
// outward unit normal there (world). False when it misses.
[[nodiscard]] bool intersect_shape(const SceneShape& shape, const cv::Vec3d& c, const cv::Vec3d& d,
                                   double s_min, double& s, cv::Vec3d& normal);

// Per column of a camera's pixels the range of their undistorted normalized x, per row that of
// y: what a shape's rectangle in normalized coordinates covers in pixels.
struct RayBounds {
  std::vector<float> col_lo, col_hi;  // per column x
  std::vector<float> row_lo, row_hi;  // per row y
};
[[nodiscard]] RayBounds ray_bounds(const cv::Mat& rays);

struct ShapeDrawing {
  double skin_grey = 175.0;  // albedo of the shapes, grey levels at full light
  double table_z_mm = 0.0;   // the table's top (world z): the shapes' parts below it are hidden
  // Rays cast on every lattice_px-th pixel and row, the pixels between interpolated where the
  // four around them meet the shape (the depth off by up to ~1 mm over a 4 px cell on a fingertip
  // 0.6 m away); 1: every pixel cast, exact.
  int lattice_px = 4;
};

// Draws SHAPES into camera CAM's grey radiance IMAGE (CV_32F): each pixel's nearest shape surface
// where it is nearer than SHEET_DEPTH (CV_32F camera z, +inf: no sheet) and above the table.
// RAYS: the undistorted normalized (x, y) per pixel (CV_32FC2), BOUNDS its ray_bounds. SHAPE_DEPTH
// (CV_32F, camera z of the shape drawn, +inf elsewhere) and MASK (CV_8U, 255 where a shape is
// drawn) are written where a shape is drawn; the caller initialises them (camera size).
void draw_shapes(const Camera& cam, const cv::Mat& rays, const RayBounds& bounds,
                 std::span<const SceneShape> shapes, const ShapeDrawing& drawing,
                 const cv::Mat& sheet_depth, cv::Mat& image, cv::Mat& shape_depth, cv::Mat& mask);

}  // namespace crease::vision
