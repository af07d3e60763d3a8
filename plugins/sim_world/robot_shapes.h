// The robot's collision shapes as the world moves them: each URDF <collision> of both sides
// (plugins/robot_model/collision_shapes.h) with its link, its material's friction against paper
// and contact stiffness, its role (tactile pad, finger back, fingertip, palm, ...), and its pose
// at the start and the end of the current world step (a shape moves smoothly in between:
// pose_at). Built at configure time; the poses are updated every step (RT).
#pragma once

#include <kdl/frames.hpp>

#include <array>
#include <vector>

#include "core/port_types/world_shapes.h"
#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/randomise.h"
#include "plugins/sim_world/shape_geometry.h"
#include "plugins/sim_world/side_kinematics.h"
#include "plugins/sim_world/world_params.h"

namespace crease::world {

enum class ShapeRole : unsigned char {
  pad,        // a fingertip's tactile pad (<f>pad)
  back,       // a fingertip's back (<f>back)
  fingertip,  // the distal phalanx's cover (<f>distal)
  finger,     // the other phalanges and knuckles
  palm,
  hand,       // wrist and forearm: moved by the wrist joints or the arm only
  arm,        // the arm's links: kinematic
};

struct WorldShape {
  Geom geom;
  int side = 0;  // robot::Side
  int link = -1;  // SideKinematics link index
  int body = -1;  // its rigid body (SideKinematics::body_of): shapes of one body never pinch
  KDL::Frame link_from_shape;
  double friction = 0;  // Coulomb coefficient against paper (randomised)
  double stiffness_n_per_mm3 = 0;  // contact stiffness per mm^2 of contact (WorldParams)
  bool compliant = false;  // moved by a hand joint: its contacts deflect the hand
  int fingertip = -1;      // 0..4 (ff mf rf lf th) for pad, back and fingertip, else -1
  int finger = -1;         // 0..4 for every link of that finger (knuckle to pad), else -1
  ShapeRole role = ShapeRole::arm;
  Pose pose0, pose1;       // at the step's start and end, world mm
  double quat0[4] = {1, 0, 0, 0}, quat1[4] = {1, 0, 0, 0};  // their rotations, (w, x, y, z)

  // The pose a fraction a in [0, 1] through the step: position linear, rotation normalised
  // linear between the two quaternions (shapes turn by well under a radian per step). RT.
  [[nodiscard]] Pose pose_at(double a) const noexcept;
};

// Non-RT. Throws crease::ConfigError for a material without a contact stiffness.
[[nodiscard]] std::vector<WorldShape> build_robot_shapes(const robot::RobotModel& model,
                                                         const std::array<const SideKinematics*, robot::kSides>& kin,
                                                         const WorldDraws& draws, const WorldParams& params);

// RT: pose0 := pose1, pose1 := the shape's pose from KIN (already updated to the step's end).
// first: both poses from KIN (no motion).
void advance_shape_poses_rt(std::vector<WorldShape>& shapes, const std::array<const SideKinematics*, robot::kSides>& kin,
                            bool first) noexcept;

// RT: every shape (up to WorldShapes::kCapacity) at its pose at the step's end (pose1) into OUT,
// with its kind, dimensions, role and side; OUT's stamp and step are the caller's.
void export_shapes_rt(const std::vector<WorldShape>& shapes, WorldShapes& out) noexcept;

}  // namespace crease::world
