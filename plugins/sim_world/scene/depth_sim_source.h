// The simulated RGB-D cameras: a CameraSource (plugins/cameras/camera_source.h) whose frames are,
// per calibrated depth camera, the 16-bit depth and the registered BGR colour image of the sheet
// mesh the scene holds for that frame (depth_view.h: the D4xx noise model), in the channel order
// of plugins/camera_rig/depth_camera.h. The `camera_depth_sim` plugin feeds it the `sheet_truth`
// port. A camera the robot carries (DepthCamera::mount: a wrist camera) is rendered each frame from
// where the world's shapes of that frame put its mount shape (carried_camera.h); when they hold no
// such shape (none received yet) its images are left empty (nothing delivered) and counted; each
// frame carries the pose it was rendered from (Frame::poses) for the depth path and the recorder.
// Not RT code: it runs on a camera worker thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "plugins/camera_rig/depth_camera.h"
#include "plugins/cameras/camera_source.h"
#include "plugins/sim_world/scene/depth_view.h"
#include "plugins/sim_world/scene/sheet_mesh.h"
#include "plugins/sim_world/scene/view_renderer.h"

namespace crease::vision {

class DepthSimSource final : public CameraSource {
 public:
  // plain: the sheet in colour.sheet_bgr (a uniform texture), else the marker faces given.
  // Frame i is stamped with its mesh's time when it has one, else start_ns + i * period_ns;
  // its noise seed is render.seed + i.
  DepthSimSource(std::vector<DepthCamera> cameras, const cv::Mat& front, const cv::Mat& back,
                 double tex_px_per_mm, std::function<SheetMesh(std::uint64_t)> mesh_at,
                 RenderOptions render, DepthSensorModel sensor, DepthColourModel colour,
                 std::int64_t period_ns, std::int64_t start_ns = 0);
  [[nodiscard]] const std::vector<Camera>& cameras() const override { return cams_; }
  [[nodiscard]] std::vector<double> depth_units_mm() const override {
    std::vector<double> u;
    for (const DepthCamera& c : depth_cams_) u.push_back(c.depth_unit_mm);
    return u;
  }
  [[nodiscard]] std::vector<crease::frames::CameraSpec> channel_images() const override {
    return depth_channel_specs(cams_);
  }
  [[nodiscard]] std::vector<std::optional<CameraMount>> mounts() const override {
    std::vector<std::optional<CameraMount>> m;
    for (const DepthCamera& c : depth_cams_) m.push_back(c.mount);
    return m;
  }
  // Never ends. With a carried camera, frame.poses holds each image's camera pose: a carried
  // camera's where it was rendered from (carried, world-from-camera), a fixed one's `fixed`.
  bool grab(Frame& frame) override;
  // Before the first grab: `shapes_now(out)` fills OUT with the world's shapes to draw in the
  // next frame (empty: none), at their real depth (depth_view.h).
  void set_shapes_source(std::function<void(std::vector<SceneShape>&)> shapes_now) {
    shapes_now_ = std::move(shapes_now);
  }

  // Any thread: frames of carried cameras rendered or skipped (one per camera per frame), and of
  // those the ones skipped for want of their mount shape.
  [[nodiscard]] std::uint64_t carried_frames() const noexcept {
    return carried_frames_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t carried_unposed() const noexcept {
    return carried_unposed_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] bool any_carried() const noexcept { return any_carried_; }

  // A plain sheet's texture (uniform white) for the constructor's front and back.
  [[nodiscard]] static cv::Mat plain_texture(double w_mm, double h_mm, double px_per_mm);

 private:
  std::vector<DepthCamera> depth_cams_;
  std::vector<Camera> cams_;   // as calibrated (a carried camera's pose relative to its mount)
  std::vector<Camera> posed_;  // where each camera is this frame (worker thread)
  bool any_carried_ = false;
  std::atomic<std::uint64_t> carried_frames_{0}, carried_unposed_{0};
  std::vector<cv::Mat> rays_;
  ViewRenderer renderer_;
  std::function<SheetMesh(std::uint64_t)> mesh_at_;
  RenderOptions render_;
  DepthSensorModel sensor_;
  DepthColourModel colour_;
  std::int64_t period_ns_;
  std::int64_t start_ns_;
  std::uint64_t next_ = 0;
  RenderedView view_;
  std::function<void(std::vector<SceneShape>&)> shapes_now_;
  std::vector<SceneShape> shapes_;
};

}  // namespace crease::vision
