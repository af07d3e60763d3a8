// The simulated cameras' scene for the tests of vision, the cameras and the calibration: the
// default double-sided marker layout, its textures, the seed-000 rig and a renderer, and the
// true image position of a layout point.
#pragma once

#include <memory>

#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/marker_layout.h"
#include "plugins/camera_rig/marker_sheet.h"
#include "plugins/sim_world/scene/sheet_mesh.h"
#include "plugins/sim_world/scene/view_renderer.h"

namespace crease::vision::testing {

struct Scene {
  MarkerLayout layout;
  std::unique_ptr<ViewRenderer> renderer;
  static constexpr double kTexPpm = 8.0;

  Scene() {
    LayoutSpec spec;
    spec.double_sided = true;
    layout = make_layout(spec);
    renderer = std::make_unique<ViewRenderer>(face_texture(layout, Face::kFront, kTexPpm),
                                              face_texture(layout, Face::kBack, kTexPpm), kTexPpm,
                                              default_rig());
  }
  [[nodiscard]] SheetMesh flat() const {
    return flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
  }
};

// True image position of a layout point on the mesh (pixels), false if behind the camera.
inline bool true_pixel(const Camera& cam, const SheetMesh& mesh, const cv::Point2d& uv,
                       cv::Point2d& px) {
  return cam.project(mesh.world_at(uv.x, uv.y), px);
}

}  // namespace crease::vision::testing
