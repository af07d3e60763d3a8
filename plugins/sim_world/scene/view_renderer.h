// Synthetic camera views of the marker sheet: the face textures mapped onto a SheetMesh for
// each calibrated camera, exact per pixel (ray / triangle intersection through the camera's
// distortion), prefiltered by a texture pyramid, with shading, the world's arms and hands
// (shape_view.h) or random hand-like occluders, blur, exposure and noise. Deterministic for a
// seed. Not RT code (it allocates on first use).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "plugins/camera_rig/camera_model.h"
#include "plugins/sim_world/scene/shape_view.h"
#include "plugins/sim_world/scene/sheet_mesh.h"

namespace crease::vision {

struct RenderOptions {
  std::uint64_t seed = 1;
  double noise_sigma = 2.0;    // Gaussian noise, grey levels
  double blur_sigma_px = 0.6;  // optics; 0 = none
  double exposure = 1.0;       // gain on scene radiance
  int occluders = 0;           // random hand-like occluders over the sheet (drawn over everything)
  double table_z_mm = 0.0;     // the table's top: the world's shapes below it are hidden
  int shape_lattice_px = 4;    // the world's shapes cast every this many px (shape_view.h); 1: exact
  bool clutter = false;        // busy background (boxes, lines, code-like grids)
};

struct RenderedView {
  cv::Mat image;           // CV_8UC1, camera size
  cv::Mat occluder_mask;   // CV_8UC1, 255 where an occluder (a world shape or a random one) hides
                           // the scene
  cv::Mat depth;  // CV_32FC1, camera-frame z of the sheet (mm), +inf elsewhere (also under a shape)
  cv::Mat shape_depth;  // CV_32FC1, camera-frame z of the world's shape seen (mm), +inf elsewhere;
                        // empty when no shapes were given
};

class ViewRenderer {
 public:
  // front / back: CV_8UC1 textures in FRONT sheet coordinates (face_texture()), px_per_mm.
  ViewRenderer(const cv::Mat& front, const cv::Mat& back, double tex_px_per_mm,
               std::vector<Camera> cameras);

  [[nodiscard]] const std::vector<Camera>& cameras() const { return cameras_; }
  // Moves camera `cam` to the world -> camera pose (R, t) for the renders that follow (a camera
  // the robot carries); its intrinsics and rays stay. No allocation; not while rendering.
  void set_pose(int cam, const cv::Matx33d& R, const cv::Vec3d& t) {
    Camera& c = cameras_.at(static_cast<std::size_t>(cam));
    c.R = R;
    c.t = t;
  }
  // Renders camera `cam` seeing `mesh` and the world's `shapes` (the arms and hands: skin-coloured
  // occluders of their real geometry, depth-tested against the sheet); the seed is mixed with
  // the camera index.
  void render(int cam, const SheetMesh& mesh, const RenderOptions& opt, RenderedView& out,
              std::span<const SceneShape> shapes = {}) const;
  // The undistorted normalized (x, y) of every pixel of camera `cam` (CV_32FC2).
  [[nodiscard]] const cv::Mat& rays(int cam) const {
    return rays_.at(static_cast<std::size_t>(cam));
  }

 private:
  std::vector<cv::Mat> front_pyr_, back_pyr_;  // CV_32F, level L halves level L-1
  double ppm_;
  std::vector<Camera> cameras_;
  std::vector<cv::Mat> rays_;  // per camera CV_32FC2: undistorted normalized (x, y) per pixel
  std::vector<RayBounds> ray_bounds_;  // per camera: its rays' ranges per column and row
};

// A random busy scene with no tag of `layout_ids` (for false-positive tests): boxes, lines,
// text, checkerboards, random bit grids with a black border and tags of other ids / other
// dictionaries. Deterministic for a seed.
cv::Mat render_clutter(int width, int height, std::uint64_t seed, int max_layout_id);

}  // namespace crease::vision
