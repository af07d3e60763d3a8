// A camera carried by the robot (a Realsense D405-like wrist camera): its calibration's extrinsics
// are relative to one collision shape of an arm or hand as the world publishes them on the
// `world_shapes` port (core/port_types/world_shapes.h), not to the world:
//   x_camera = rotation * x_shape + translation   (mm)
// The shape is named by three keys of the same OpenCV FileStorage calibration file:
//   mount_side: right | left                      (WorldShapes::Shape::side 0 | 1)
//   mount_role: pad | back | fingertip | finger | palm | hand | arm   (WorldShapes::Role)
//   mount_index: N                                the N-th shape of that role on that side, in
//                                                 the port's order (default 0)
// A shape is rigid on its link (the world fixes link_from_shape), so a mount on a shape is a mount
// on its link: e.g. role `hand`, index 1 is the forearm's capsule (config/robot/crease_robot.urdf:
// the forearm's cylinder, its capsule, the wrist). A file without `mount_side` is a camera fixed in
// the world. Non-RT (configure time) but for place_on_mount (RT-safe, no allocation).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "core/frames/frame_channel.h"
#include "core/port_types/world_shapes.h"

namespace crease::vision {

struct CameraMount {
  std::uint8_t side = 0;  // 0 right, 1 left
  crease::WorldShapes::Role role = crease::WorldShapes::Role::hand;
  int index = 0;  // among the shapes of that role and side, in the port's order
};

// The mount keys of the calibration file at PATH; nullopt when it has no `mount_side`. Throws
// crease::ConfigError "<path>: key '<key>': <reason>" (as load_camera does) for an unknown side or
// role, a negative index, or a `mount_role` / `mount_index` without `mount_side`.
[[nodiscard]] std::optional<CameraMount> load_camera_mount(const std::string& path);
// Appends the mount keys to the calibration file at PATH (written by save_camera).
void save_camera_mount(const CameraMount& mount, const std::string& path);

// "right hand #1": the mount as a person reads it, for messages.
[[nodiscard]] std::string describe(const CameraMount& mount);

// The carried camera's world -> camera pose (R, t) when its mount shape has the world pose
// (shape_R: the shape's axes in the world, x_world = shape_R * x_shape + shape_p, mm); mount_R,
// mount_t: the calibration's shape -> camera pose. RT-safe.
void place_on_mount(const cv::Matx33d& mount_R, const cv::Vec3d& mount_t,
                    const cv::Matx33d& shape_R, const cv::Vec3d& shape_p, cv::Matx33d& R,
                    cv::Vec3d& t) noexcept;

// A frame's camera pose (core/frames/frame_channel.h: world-from-camera, carried) of a camera
// whose world -> camera pose this capture is (R, t). RT-safe.
[[nodiscard]] crease::frames::CameraPose carried_pose(const cv::Matx33d& R,
                                                      const cv::Vec3d& t) noexcept;
// The world -> camera pose (R, t) of a frame's carried camera pose; false, R and t untouched,
// when any entry is not finite or the rotation is not one (|R^T R - I| > 1e-6 in an entry, or
// det R < 0). RT-safe.
[[nodiscard]] bool camera_from_pose(const crease::frames::CameraPose& pose, cv::Matx33d& R,
                                    cv::Vec3d& t) noexcept;

}  // namespace crease::vision
