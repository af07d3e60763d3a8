// Ground truth for rendered views: which markers a camera should detect and where their
// corners project. Used by the tests and crease-bench vision.
#pragma once

#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/marker_layout.h"
#include "plugins/sim_world/scene/sheet_mesh.h"
#include "plugins/sim_world/scene/view_renderer.h"

namespace crease::vision {

struct VisibleMarker {
  int id = -1;
  std::array<cv::Point2d, 4> corners_px;  // true projections, detector order
  double min_side_px = 0;
};

// Markers of `layout` that camera `cam` sees in `view`: printed face towards the camera
// (cosine >= min_cos), all corners inside the image with a margin, no occluder pixel near
// the tag, not hidden by another part of the sheet, not bent by a fold, shortest side >= min_side_px.
std::vector<VisibleMarker> visible_markers(const Camera& cam, const SheetMesh& mesh, const MarkerLayout& layout,
                                           const RenderedView& view, double min_side_px = 24.0,
                                           double min_cos = 0.35);

}  // namespace crease::vision
