// One kinematic chain from the world to a frame of the robot (a tool frame or any link), with
// its KDL forward-kinematics solver and the map from the drivers' joint arrays to the chain's
// joints. Built at load time (allocates); pose_m() is RT: it allocates nothing, takes no lock,
// never throws.
//
// A chain's joints are an arm's (index into the arm's 7, drivers/README.md §4) or a hand's
// (index into the hand's 20, §3); a URDF <mimic> joint reads its master's angle:
// q = multiplier * q_master + offset.
#pragma once

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "plugins/robot_model/robot_layout.h"

namespace crease::robot {

struct JointSource {
  enum Kind : std::uint8_t { arm, hand };
  Kind kind = arm;
  int index = 0;            // into the arm's 7 or the hand's 20 joint angles
  double multiplier = 1.0;  // a mimic joint's; 1 otherwise
  double offset = 0.0;      // rad
};

using ArmAngles = std::span<const double, kArmJoints>;    // rad, §4 order
using HandAngles = std::span<const double, kHandJoints>;  // rad, §3 order

class ToolChain {
 public:
  // SOURCES: one per movable joint of CHAIN, in chain order, each index within its arm's or
  // hand's joints (CREASE_DEMAND: RobotModel builds them from the validated model). Non-RT.
  ToolChain(std::string tip, const KDL::Chain& chain, std::vector<JointSource> sources);
  ToolChain(ToolChain&&) = default;
  ToolChain& operator=(ToolChain&&) = default;
  ToolChain(const ToolChain&) = delete;
  ToolChain& operator=(const ToolChain&) = delete;

  // RT. The tip's pose in the world frame, metres (URDF's unit), from one side's arm and hand
  // joint angles. False only if KDL reports an error (not expected: sizes are fixed at load).
  // Not for concurrent calls on one chain (it fills a joint array it owns).
  [[nodiscard]] bool pose_m(ArmAngles arm, HandAngles hand, KDL::Frame& out) noexcept;

  // The chain's own joint angles for a configuration (Q must have one row per chain joint),
  // for use with KDL's other solvers. RT.
  void chain_angles(ArmAngles arm, HandAngles hand, KDL::JntArray& q) const noexcept;

  [[nodiscard]] const std::string& tip() const noexcept { return tip_; }
  [[nodiscard]] const KDL::Chain& chain() const noexcept { return *chain_; }
  [[nodiscard]] const std::vector<JointSource>& sources() const noexcept { return sources_; }

 private:
  std::string tip_;
  std::unique_ptr<KDL::Chain> chain_;  // heap: the solver keeps a reference to it
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> fk_;
  KDL::JntArray q_;
  std::vector<JointSource> sources_;
};

}  // namespace crease::robot
