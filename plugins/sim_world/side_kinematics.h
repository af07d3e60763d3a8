// Forward kinematics of one side of the robot (arm and hand) in one pass over its KDL tree,
// and the hand joints' Jacobian at any point of any link: what the world needs every 1 ms for
// ~45 links, where robot_model's per-chain solvers would walk from the world once per link.
//
// Built at configure time from RobotModel's KDL tree (plugins/robot_model): the side's
// segments in tree order (parents first), each with its joint's source (an arm joint, a hand
// joint, or a <mimic> of one: q = multiplier * q_master + offset; fixed joints have none).
// update_rt() poses every segment; poses in the world frame, millimetres (the world's unit;
// KDL and the URDF are in metres). RT: update_rt and the queries allocate nothing.
#pragma once

#include <kdl/frames.hpp>
#include <kdl/segment.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "plugins/robot_model/robot_layout.h"
#include "plugins/robot_model/robot_model.h"
#include "plugins/sim_world/shape_geometry.h"

namespace crease::world {

class SideKinematics {
 public:
  // Non-RT. Throws crease::ConfigError when the side's joints are missing from the tree.
  SideKinematics(const robot::RobotModel& model, robot::Side side);

  // RT. Poses every link of the side from the arm's 7 and the hand's 20 angles (rad).
  void update_rt(robot::ArmAngles arm, robot::HandAngles hand) noexcept;

  // Non-RT: the index of link NAME (with its prefix), -1 if not on this side.
  [[nodiscard]] int link_index(std::string_view name) const noexcept;
  [[nodiscard]] int link_count() const noexcept { return static_cast<int>(seg_.size()); }
  [[nodiscard]] const std::string& link_name(int link) const noexcept { return seg_[link].name; }

  // After update_rt: the link's frame in the world (mm), and its pose composed with a fixed
  // offset (a collision shape's link_from_shape, metres as the URDF). RT.
  [[nodiscard]] const Pose& link_pose(int link) const noexcept { return pose_[link]; }
  [[nodiscard]] Pose compose(int link, const KDL::Frame& link_from_x_m) const noexcept;

  // The rigid body a link belongs to: the nearest link at or above it whose joint moves (links
  // on fixed joints, as the pads on their distal phalanx, share it); -1: fixed to the world.
  [[nodiscard]] int body_of(int link) const noexcept { return seg_[link].body; }
  // True when some hand joint moves the link (the hand's links, from the wrist on).
  [[nodiscard]] bool moved_by_hand(int link) const noexcept { return seg_[link].hand_anc_count > 0; }

  // After update_rt: g = J(p)^T f for a force f (any unit) applied at world point p (mm) on
  // the link: the 20 hand joints' generalized force (f's unit x mm / rad). Arm joints do not
  // appear (the arm is position-controlled, kinematic). Adds to g. RT.
  void add_hand_jacobian_transpose(int link, Vec3 p_mm, Vec3 f, std::span<double, robot::kHandJoints> g) const noexcept;
  // After update_rt: g += J^T [f; m] for a wrench on the link, force f (N) and moment m about
  // the world origin (N mm): per hand joint, axis . (m - origin x f). RT.
  void add_hand_wrench_transpose(int link, Vec3 f, Vec3 m, std::span<double, robot::kHandJoints> g) const noexcept;
  // After update_rt: the displacement (mm) of world point p fixed to the link for hand joint
  // changes dq (rad): J(p) dq. RT.
  [[nodiscard]] Vec3 hand_jacobian_times(int link, Vec3 p_mm, std::span<const double, robot::kHandJoints> dq) const noexcept;

 private:
  struct Source {
    enum Kind : unsigned char { none, arm, hand } kind = none;
    int index = 0;
    double multiplier = 1.0, offset = 0.0;
  };
  static constexpr int kMaxAncestors = 12;
  struct Seg {
    std::string name;
    KDL::Segment segment;
    int parent = -1;  // -1: the world frame
    int body = -1;    // see body_of
    Source source;
    // The movable hand-joint segments between the world and this link (this one included).
    std::array<int, kMaxAncestors> hand_anc{};
    int hand_anc_count = 0;
  };

  std::vector<Seg> seg_;
  std::vector<KDL::Frame> frame_;  // world <- segment tip, metres
  std::vector<Pose> pose_;         // the same, mm
  std::vector<Vec3> axis_, origin_;  // movable segments: joint axis (unit) and a point on it, world mm
  // update_rt recomputes a segment only if its joint value or a segment above it changed since
  // the last call (a step poses the arm three times with the same arm angles).
  std::vector<double> last_q_;
  std::vector<std::uint8_t> moved_;
  bool posed_ = false;
};

}  // namespace crease::world
