// Test support for the wrist cameras in loops (config/wrist_cameras, carried on the forearms'
// capsules): the `world_shapes` port's forearm of one side placed so that its wrist camera looks
// straight down from a chosen point, as the world would publish it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <opencv2/core.hpp>

#include "core/port_types/world_shapes.h"
#include "plugins/camera_rig/camera_model.h"

namespace wrist_shapes {

// The right (side 0) or left forearm's cylinder and capsule (role hand, config/robot/
// crease_robot.urdf) placed so that the wrist camera CAM, mounted on the capsule, looks straight
// down from c_w (world mm; image x along the world's x): out.shapes[first], out.shapes[first + 1].
inline void forearm_carrying(const crease::vision::Camera& cam, int side, const cv::Vec3d& c_w,
                             crease::WorldShapes& out, std::uint32_t first) {
  const cv::Matx33d R_wc(1, 0, 0, 0, -1, 0, 0, 0, -1);
  const cv::Matx33d R_s = R_wc.t() * cam.R;
  const cv::Vec3d p_s = c_w + R_s * (cam.R.t() * cam.t);
  const cv::Vec3d centres[2] = {p_s + R_s * cv::Vec3d(0, 5, -105), p_s};
  for (std::uint32_t k = 0; k < 2; ++k) {
    crease::WorldShapes::Shape& s = out.shapes[first + k];
    s.kind = k == 0 ? crease::WorldShapes::Kind::cylinder : crease::WorldShapes::Kind::capsule;
    s.role = crease::WorldShapes::Role::hand;
    s.side = static_cast<std::uint8_t>(side);
    s.radius_mm = k == 0 ? 67.5f : 45.f;
    s.half_length_mm = k == 0 ? 5.f : 55.f;
    for (int i = 0; i < 3; ++i) s.position_mm[i] = static_cast<float>(centres[k][i]);
    for (int i = 0; i < 9; ++i) s.rotation[i] = static_cast<float>(R_s.val[i]);
  }
  out.count = std::max(out.count, first + 2);
}

}  // namespace wrist_shapes
