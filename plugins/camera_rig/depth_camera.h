// An RGB-D camera (Realsense D4xx-like): the calibrated camera of its depth image (the colour
// image is registered to it: same size, intrinsics and pose) and the depth unit, in the colour
// cameras' OpenCV FileStorage format plus one key:
//   depth_unit_mm: 1.0     one count of the 16-bit depth image, mm (D435 default 1 mm, D405 0.1 mm)
// and, for a camera the robot carries (a wrist camera), the mount keys of camera_mount.h: then the
// file's rotation and translation are relative to that shape of the robot, not to the world;
// and the frame channel its sets travel in (port `depth_images`, kind frames): per camera K two
// images, "<name>.depth" (16-bit counts, 0 = no depth) then "<name>.colour" (8-bit BGR). Both
// ends (camera_depth_sim, depth_tracking) bind it here. Non-RT (configure time).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/frames/frame_channel.h"
#include "core/port_binder.h"
#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/camera_mount.h"
#include "plugins/camera_rig/images_port.h"

namespace crease::vision {

inline constexpr char kDepthImagesPort[] = "depth_images";
inline constexpr char kDepthFramesPort[] = "depth_frames";

struct DepthCamera {
  Camera camera;
  double depth_unit_mm = 1.0;
  // Carried by the robot: camera.R and camera.t map the mount shape's frame to the camera's
  // (camera_mount.h). nullopt: fixed, they map the world's.
  std::optional<CameraMount> mount;
};

// Throws crease::ConfigError "<path>: key '<key>': <reason>" as load_camera does; also when
// depth_unit_mm is missing or outside (0, 10], and for bad mount keys (camera_mount.h).
DepthCamera load_depth_camera(const std::string& path);
void save_depth_camera(const DepthCamera& cam, const std::string& path);
// DIR/cam0.yaml, DIR/cam1.yaml, ... (consecutive from 0); ConfigError when there is none.
std::vector<DepthCamera> load_depth_camera_dir(const std::string& dir);

[[nodiscard]] std::vector<Camera> cameras_of(const std::vector<DepthCamera>& cams);
// The channel's images: camera k's depth at 2k, its colour at 2k + 1.
[[nodiscard]] std::vector<crease::frames::CameraSpec> depth_channel_specs(
    const std::vector<Camera>& cameras);

// Binds the `depth_images` port (remapped like every port) with these cameras' images.
[[nodiscard]] std::shared_ptr<crease::frames::FrameChannel> bind_depth_images(
    crease::PortBinder& ports, const std::vector<Camera>& cameras, ImagesEnd end);

}  // namespace crease::vision
