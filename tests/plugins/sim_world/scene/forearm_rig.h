// Test support for cameras the robot carries (plugins/sim_world/scene/carried_camera.h): the right
// forearm's shapes as the world publishes them (config/robot/crease_robot.urdf: its cylinder, then
// its capsule, role hand), placed so that a wrist camera mounted on the capsule (hand #1) stands at
// a chosen world pose, and a D405's noise model as camera_depth_sim's `sensor: d405` sets it.
#pragma once

#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "plugins/camera_rig/camera_model.h"
#include "plugins/sim_world/scene/depth_view.h"
#include "plugins/sim_world/scene/shape_view.h"

namespace forearm_rig {

using crease::vision::Camera;
using crease::vision::SceneShape;
using Role = crease::WorldShapes::Role;

// World -> camera rotation looking straight down (image x along the world's x), then turned by
// tilt_deg about the camera's own x.
inline cv::Matx33d looking_down(double tilt_deg) {
  const double a = tilt_deg * CV_PI / 180, c = std::cos(a), s = std::sin(a);
  return cv::Matx33d(1, 0, 0, 0, c, -s, 0, s, c) * cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1);
}

inline SceneShape shape(crease::world::GeomKind kind, double radius, double half_length, Role role,
                        int side) {
  SceneShape s;
  s.geom.kind = kind;
  s.geom.radius_mm = radius;
  s.geom.half_length_mm = half_length;
  s.role = role;
  s.side = static_cast<std::uint8_t>(side);
  return s;
}

inline void set_pose(SceneShape& s, const cv::Matx33d& R, const cv::Vec3d& p) {
  for (int k = 0; k < 9; ++k) s.pose.r[k] = R.val[k];
  s.pose.t = {p[0], p[1], p[2]};
}

// The right forearm placed so that CAM, mounted on its capsule, is at the world pose R_wc (world
// -> camera) with its centre at c_w.
inline std::vector<SceneShape> forearm_carrying(const Camera& cam, const cv::Matx33d& R_wc,
                                                const cv::Vec3d& c_w) {
  const cv::Matx33d R_s = R_wc.t() * cam.R;    // the capsule's axes: cam.R * R_s^T = R_wc
  const cv::Vec3d c_s = -(cam.R.t() * cam.t);  // the camera's centre in the capsule's frame
  const cv::Vec3d p_s = c_w - R_s * c_s;
  SceneShape disc = shape(crease::world::GeomKind::cylinder, 67.5, 5, Role::hand, 0);
  SceneShape capsule = shape(crease::world::GeomKind::capsule, 45, 55, Role::hand, 0);
  set_pose(capsule, R_s, p_s);
  set_pose(disc, R_s, p_s + R_s * cv::Vec3d(0, 5, -105));  // the forearm's origin side
  return {disc, capsule};
}

inline crease::vision::DepthSensorModel d405() {
  crease::vision::DepthSensorModel sm;  // camera_depth_sim's `sensor: d405`
  sm.baseline_mm = 18;
  sm.min_range_mm = 70;
  sm.max_range_mm = 500;
  return sm;
}

}  // namespace forearm_rig
