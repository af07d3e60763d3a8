// A camera the robot carries (plugins/camera_rig/camera_mount.h) placed where the world's shapes
// of this frame put it: its mount shape found among them (by side, role and index, in the port's
// order) and the shape's world pose composed with the calibration's shape -> camera pose.
// Not RT code (a camera worker's), but it allocates nothing.
#pragma once

#include <span>

#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/camera_mount.h"
#include "plugins/sim_world/scene/shape_view.h"

namespace crease::vision {

// The index in SHAPES of MOUNT's shape; -1 when they hold no such shape (none received yet, or
// fewer shapes of that role on that side).
[[nodiscard]] int mount_shape_index(std::span<const SceneShape> shapes,
                                    const CameraMount& mount) noexcept;

// POSED := CALIBRATION (whose R, t are relative to the mount shape) at its world pose among
// SHAPES; false, POSED untouched, when the shape is not among them.
[[nodiscard]] bool place_carried_camera(const Camera& calibration, const CameraMount& mount,
                                        std::span<const SceneShape> shapes, Camera& posed) noexcept;

}  // namespace crease::vision
