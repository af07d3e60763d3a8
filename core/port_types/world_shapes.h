// Port payload `world_shapes`: the simulated world's robot as the cameras could see it
// (plugins/sim_world): every collision shape of both arms and hands, its kind, dimensions and
// pose, for the simulated cameras to draw as occluders. Shapes as
// plugins/sim_world/shape_geometry.h: sphere; capsule and cylinder along the shape's z, centred;
// box centred, its edges rounded by its smallest half extent.
// World frame, mm; x_world = rotation * x_shape + position_mm.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct WorldShapes {
  static constexpr char kPortType[] = "crease.WorldShapes";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr std::uint32_t kCapacity = 128;  // the shipped robot has 88

  enum class Kind : std::uint8_t { sphere = 0, capsule = 1, cylinder = 2, box = 3 };
  // What the shape is of (plugins/sim_world/robot_shapes.h ShapeRole).
  enum class Role : std::uint8_t {
    pad = 0,
    back = 1,
    fingertip = 2,
    finger = 3,
    palm = 4,
    hand = 5,
    arm = 6
  };

  struct Shape {
    Kind kind = Kind::sphere;
    Role role = Role::arm;
    std::uint8_t side = 0;  // 0 right, 1 left
    std::uint8_t reserved = 0;
    float radius_mm = 0;  // sphere, capsule, cylinder
    // capsule: half the distance between its caps' centres; cylinder: half its length
    float half_length_mm = 0;
    float half_mm[3] = {};                            // box: half extents
    float position_mm[3] = {};                        // the shape's centre
    float rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // its axes in the world, row-major
  };

  std::int64_t timestamp_ns = 0;  // CLOCK_MONOTONIC time of the world step the poses are of
  std::uint64_t step = 0;         // world steps since the start
  std::uint32_t count = 0;        // valid entries of shapes[]
  std::uint32_t reserved = 0;
  Shape shapes[kCapacity];

  [[nodiscard]] bool all_finite() const {
    if (count > kCapacity) return false;
    for (std::uint32_t i = 0; i < count; ++i) {
      const Shape& s = shapes[i];
      if (!std::isfinite(s.radius_mm) || !std::isfinite(s.half_length_mm)) return false;
      for (float v : s.half_mm)
        if (!std::isfinite(v)) return false;
      for (float v : s.position_mm)
        if (!std::isfinite(v)) return false;
      for (float v : s.rotation)
        if (!std::isfinite(v)) return false;
    }
    return true;
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(WorldShapes::Shape, 72, 4);
CREASE_PORT_PAYLOAD_LAYOUT(WorldShapes, 9240, 8);

}  // namespace crease
