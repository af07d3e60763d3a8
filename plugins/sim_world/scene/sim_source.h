// The simulated cameras: a CameraSource (plugins/cameras/camera_source.h) that renders, for every
// calibrated camera of a ViewRenderer, the sheet mesh the scene holds for each frame. The
// `camera_sim` plugin feeds it the `sheet_truth` port; tests and crease-bench give it meshes of
// their own. Not RT code (rendering allocates): it runs on a camera worker thread.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "plugins/cameras/camera_source.h"
#include "plugins/sim_world/scene/sheet_mesh.h"
#include "plugins/sim_world/scene/view_renderer.h"

namespace crease::vision {

// A camera that delivers nothing for a run of frames (a dropout: its image of those frame sets
// is empty, so the frame channel marks it invalid).
struct CameraDropout {
  int camera = 0;
  std::uint64_t first_frame = 0;
  std::uint64_t frames = 0;
};

// COUNT dropouts of FRAMES frames each, of cameras drawn from CAMERAS, starting at frames drawn
// from [from_frame, to_frame], all from SEED (the same every run).
[[nodiscard]] std::vector<CameraDropout> draw_dropouts(std::uint64_t seed, int count, std::uint64_t frames,
                                                       std::uint64_t from_frame, std::uint64_t to_frame, int cameras);

// Renders the mesh returned by `mesh_at(frame index)` for every camera; frame i is stamped with
// the mesh's own time when it has one (SheetMesh::timestamp_ns >= 0, e.g. the simulated world's
// truth), else start_ns + i * period_ns (pass the CLOCK_MONOTONIC start time in a running
// system). Frame i's noise seed is options.seed + i. With a shapes source (set_shapes_source)
// every frame also draws the world's arms and hands it gives at that frame.
class SimSource final : public CameraSource {
 public:
  SimSource(std::shared_ptr<const ViewRenderer> renderer,
            std::function<SheetMesh(std::uint64_t)> mesh_at, RenderOptions options,
            std::int64_t period_ns, std::int64_t start_ns = 0, std::vector<CameraDropout> dropouts = {});
  [[nodiscard]] const std::vector<Camera>& cameras() const override { return renderer_->cameras(); }
  bool grab(Frame& frame) override;  // never ends
  // Before the first grab: `shapes_now(out)` fills OUT with the shapes to draw in the next frame
  // (empty: none).
  void set_shapes_source(std::function<void(std::vector<SceneShape>&)> shapes_now) {
    shapes_now_ = std::move(shapes_now);
  }

 private:
  std::shared_ptr<const ViewRenderer> renderer_;
  std::function<SheetMesh(std::uint64_t)> mesh_at_;
  RenderOptions options_;
  std::int64_t period_ns_;
  std::int64_t start_ns_;
  std::uint64_t next_ = 0;
  std::vector<CameraDropout> dropouts_;
  std::function<void(std::vector<SceneShape>&)> shapes_now_;
  std::vector<SceneShape> shapes_;
};

}  // namespace crease::vision
