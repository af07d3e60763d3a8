// The arm's world -> flange chain for the IK's inner loop: each revolute segment as its pose at
// zero turned about its joint's axis line, precomputed from the KDL chain, so a pass down the
// chain is one sincos and two 3x3 products per joint and no call into KDL (its per-segment
// Segment::pose / Joint::pose / Frame products were ~60 % of ArmIk::track). Checked against
// KDL's Segment::pose at construction.
//
//   ArmChainRt c(chain);              // non-RT: throws ConfigError for a joint it cannot take
//   c.pass(q, axis, origin, flange);  // RT: joint axes and origins (world) and the flange pose
//
// Metres and radians. No allocation, no locks, no exceptions after construction.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <kdl/chain.hpp>
#include <vector>

#include "plugins/robot_model/robot_layout.h"

namespace crease::robot {

class ArmChainRt {
 public:
  // The chain must hold kArmJoints revolute joints (and any number of fixed segments).
  explicit ArmChainRt(const KDL::Chain& chain);

  // At arm angles Q: each joint's axis and a point of its axis line, in the world, as the pass
  // reaches it (before its own motion), and the flange's pose.
  void pass(const std::array<double, kArmJoints>& q, std::array<Eigen::Vector3d, kArmJoints>& axis,
            std::array<Eigen::Vector3d, kArmJoints>& origin,
            Eigen::Isometry3d& flange) const noexcept;

 private:
  struct Segment {
    bool revolute = false;
    Eigen::Matrix3d r0;  // the segment's pose at q = 0 (in its parent's frame)
    Eigen::Vector3d p0;
    Eigen::Vector3d a;  // its joint's axis (unit) and a point of the axis line, parent frame
    Eigen::Vector3d o;
  };
  std::vector<Segment> segments_;
};

}  // namespace crease::robot
