// What a simulated RGB-D camera (Realsense D4xx-like) makes of a rendered view: the 16-bit depth
// image and the registered BGR colour image, from the renderer's exact sheet depth
// (view_renderer.h) plus the table plane, with the device's imperfections:
//  - noise: Gaussian, RMS sigma(z) = z^2 * subpixel / (f_px * baseline_mm), Intel's formula for
//    the D400 series' depth RMS error (Grunnet-Jepsen et al., "Tuning depth cameras for best
//    performance", Intel whitepaper, rev. 2.x); D435: baseline 50 mm, subpixel 0.08 (Intel's
//    typical figure); at 848x480 f ~ 428 px, so sigma = 0.93 mm at 0.5 m, 1.6 mm at 0.65 m, 2.4 mm
//    at 0.8 m;
//  - no depth (0) where the ray meets the surface at more than max_incidence_deg from its normal
//    (grazing: no texture match) and at depth edges (a neighbour more than edge_jump_mm away:
//    the stereo matcher's invalidated band around occluding edges);
//  - quantisation to the device's depth unit (depth_unit_mm of the calibration), 0 = no depth,
//    out of [min_range_mm, max_range_mm] = no depth;
//  - the world's arms and hands (the renderer's shape depth: their real geometry) at their own
//    depth; random hand-like occluders (the rest of the renderer's occluder mask)
//    hand_height_mm above what they cover.
// Colour: the plain sheet (seed 001's origami paper) is sheet_bgr shaded as the grey render is;
// the marker sheet keeps its grey print; table grey; hands (and arms) skin-coloured.
// Deterministic for a seed. Not RT code (a worker thread's).
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "plugins/camera_rig/camera_model.h"
#include "plugins/sim_world/scene/view_renderer.h"

namespace crease::vision {

struct DepthSensorModel {
  double baseline_mm = 50.0;       // stereo baseline (D435: 50 mm; D405: 18 mm)
  double subpixel = 0.08;          // RMS disparity error, pixels (Intel's typical 0.08)
  bool noise = true;               // false: exact depth (quantised still)
  double max_incidence_deg = 78.0; // no depth beyond this angle between ray and surface normal
  double edge_jump_mm = 12.0;      // no depth where a 4-neighbour is farther off than this
  double min_range_mm = 200.0;     // D435 minimum depth at 848x480 ~ 195 mm
  double max_range_mm = 3000.0;
  double table_z_mm = 0.0;         // the table plane, world z (seen where no sheet is)
  double hand_height_mm = 40.0;    // random occluders' height above what they cover
};

struct DepthColourModel {
  bool plain = true;                     // plain-coloured sheet (else the grey marker print)
  cv::Vec3b sheet_bgr{200, 140, 40};     // plain sheet, BGR at full light (a blue paper)
  cv::Vec3b hand_bgr{120, 150, 200};     // skin
};

// RMS depth noise at z (mm) of a camera of focal length f_px.
[[nodiscard]] double depth_sigma_mm(const DepthSensorModel& m, double f_px, double z_mm) noexcept;

// view: the renderer's output for `cam` (grey image, sheet depth, occluders); rays: the camera's
// undistorted normalized (x, y) per pixel (CV_32FC2, camera size); depth_unit_mm: one count.
// Writes depth (CV_16UC1) and bgr (CV_8UC3), camera size; in place when they already are.
void make_depth_view(const Camera& cam, const cv::Mat& rays, double depth_unit_mm,
                     const RenderedView& view, const DepthSensorModel& sensor,
                     const DepthColourModel& colour, std::uint64_t seed, cv::Mat& depth,
                     cv::Mat& bgr);

// The undistorted normalized (x, y) of every pixel of `cam` (CV_32FC2). Non-RT.
[[nodiscard]] cv::Mat ray_table(const Camera& cam);

}  // namespace crease::vision
