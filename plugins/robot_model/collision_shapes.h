// The collision geometry of the robot's links, from the URDF's <collision> elements.
//
// URDF has no capsule, so the robot's URDF marks them: a <collision name="SURFACE_capsule">
// holding a <cylinder> is a capsule with hemispherical caps of the cylinder's radius centred on
// its end faces. SURFACE is `cover` (a fingertip cover) or `shell` (any other surface); the
// robot's YAML gives each side's material, and so the friction, of both. Meshes are refused.
// Metres (URDF's unit). Non-RT.
#pragma once

#include <kdl/frames.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <urdf_model/link.h>

#include "plugins/robot_model/urdf_reader.h"

namespace crease::robot {

enum class ShapeKind : std::uint8_t { sphere, box, cylinder, capsule };
enum class Surface : std::uint8_t { cover, shell };

struct CollisionShape {
  std::string link;
  ShapeKind kind = ShapeKind::sphere;
  Surface surface = Surface::shell;
  double radius_m = 0;                    // sphere, cylinder, capsule
  double length_m = 0;                    // cylinder: its length; capsule: between the cap centres
  std::array<double, 3> half_extents_m{};  // box
  KDL::Frame link_from_shape;             // the shape's pose in its link's frame; cylinder and
                                          // capsule axes along its z, centred on its origin
  double friction = 0;                    // Coulomb coefficient against paper (set by RobotModel)
};

// The shapes of LINK in file order. Throws crease::ConfigError naming the file, the link's
// line and the reason for a mesh, an unknown surface name or a non-positive size.
[[nodiscard]] std::vector<CollisionShape> collision_shapes_of(const urdf::Link& link,
                                                              const UrdfSource& source);

}  // namespace crease::robot
