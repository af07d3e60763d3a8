#include "plugins/sim_world/scene/carried_camera.h"

namespace crease::vision {

int mount_shape_index(std::span<const SceneShape> shapes, const CameraMount& mount) noexcept {
  int seen = 0;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const SceneShape& s = shapes[i];
    if (s.side != mount.side || s.role != mount.role) continue;
    if (seen++ == mount.index) return static_cast<int>(i);
  }
  return -1;
}

bool place_carried_camera(const Camera& calibration, const CameraMount& mount,
                          std::span<const SceneShape> shapes, Camera& posed) noexcept {
  const int i = mount_shape_index(shapes, mount);
  if (i < 0) return false;
  const world::Pose& p = shapes[static_cast<std::size_t>(i)].pose;
  const cv::Matx33d shape_R(p.r[0], p.r[1], p.r[2], p.r[3], p.r[4], p.r[5], p.r[6], p.r[7], p.r[8]);
  place_on_mount(calibration.R, calibration.t, shape_R, cv::Vec3d(p.t.x, p.t.y, p.t.z), posed.R,
                 posed.t);
  return true;
}

}  // namespace crease::vision
