// The robot's kinematic and collision model, loaded from its parameter file and the URDF that
// file names (config/robot/crease_robot.yaml, crease_robot.urdf), for the controllers and the
// simulated world alike.
//
//   RobotModel m = RobotModel::load("config/robot/crease_robot.yaml");   // non-RT, throws
//   KDL::Frame pad;
//   m.tool_pose_m(Side::right, ToolFrame::ff_pad, arm_q, hand_q, pad);   // RT
//
// load() parses the URDF with urdfdom, replaces each arm's mounting with the YAML's, builds the
// KDL tree (kdl_parser), checks that each side has its 7 arm joints (S1..W2) and 20 hand joints
// (drivers/README.md §3 order) with limits, that every other movable joint is a <mimic> of a
// hand joint, and that every tool frame exists; then builds one chain and FK solver per side
// and tool frame. A malformed file throws crease::ConfigError naming the file, the line and the
// element (the URDF) or the key (the YAML).
//
// Units: metres and radians inside (KDL's and URDF's), the names say so; the YAML's
// millimetres and degrees are converted on load.
#pragma once

#include <kdl/tree.hpp>

#include <array>
#include <map>
#include <string>
#include <vector>

#include "plugins/robot_model/collision_shapes.h"
#include "plugins/robot_model/robot_layout.h"
#include "plugins/robot_model/robot_params.h"
#include "plugins/robot_model/tool_chain.h"

namespace crease::robot {

struct JointInfo {
  std::string name;  // with the side's prefix
  double lower_rad = 0;
  double upper_rad = 0;
  double velocity_rad_s = 0;
  double effort_nm = 0;  // nominal (URDF requires one); the kinematics does not use it
};

// A URDF joint that follows a hand joint: q = multiplier * q[master] + offset.
struct MimicJoint {
  std::string name;
  int master = 0;  // index into the hand's 20
  double multiplier = 1.0;
  double offset = 0.0;
};

class RobotModel {
 public:
  // Non-RT. Throws crease::ConfigError.
  [[nodiscard]] static RobotModel load(const std::string& yaml_path);

  RobotModel(RobotModel&&) = default;
  RobotModel& operator=(RobotModel&&) = default;

  [[nodiscard]] const RobotParams& params() const noexcept { return params_; }
  [[nodiscard]] const std::string& urdf_file() const noexcept { return params_.urdf_path; }
  [[nodiscard]] const KDL::Tree& tree() const noexcept { return tree_; }

  [[nodiscard]] const std::vector<JointInfo>& arm_joints(Side s) const noexcept {
    return sides_[index(s)].arm;
  }
  [[nodiscard]] const std::vector<JointInfo>& hand_joints(Side s) const noexcept {
    return sides_[index(s)].hand;
  }
  [[nodiscard]] const std::vector<MimicJoint>& hand_mimics(Side s) const noexcept {
    return sides_[index(s)].mimics;
  }
  // world <- arm base as loaded (the YAML's mounting), metres.
  [[nodiscard]] const KDL::Frame& mount(Side s) const noexcept { return sides_[index(s)].mount; }

  // Every link's collision shapes, the links in URDF file order, with each shape's friction
  // against paper from its side's cover or shell material.
  [[nodiscard]] const std::vector<CollisionShape>& collision_shapes() const noexcept { return shapes_; }
  // The shapes of one link (empty if it has none). Non-RT.
  [[nodiscard]] std::vector<CollisionShape> shapes_of(const std::string& link) const;

  // The prebuilt chain of a tool frame.
  [[nodiscard]] ToolChain& tool(Side s, ToolFrame f) noexcept {
    return sides_[index(s)].tools[static_cast<int>(f)];
  }
  // RT: a tool frame's pose in the world, metres. See ToolChain::pose_m.
  [[nodiscard]] bool tool_pose_m(Side s, ToolFrame f, ArmAngles arm, HandAngles hand,
                                 KDL::Frame& out) noexcept {
    return tool(s, f).pose_m(arm, hand, out);
  }
  // A chain from the world to any link of side S, e.g. for a collision shape. Non-RT; throws
  // crease::ConfigError for a link that is not on that side.
  [[nodiscard]] ToolChain make_chain(Side s, const std::string& link) const;

 private:
  struct SideModel {
    std::vector<JointInfo> arm, hand;
    std::vector<MimicJoint> mimics;
    KDL::Frame mount;
    std::map<std::string, JointSource> sources;  // every movable joint of this side, by name
    std::vector<ToolChain> tools;                // indexed by ToolFrame
  };
  RobotModel() = default;
  static constexpr int index(Side s) noexcept { return static_cast<int>(s); }

  RobotParams params_;
  UrdfSource source_;
  KDL::Tree tree_;
  std::array<SideModel, kSides> sides_;
  std::vector<CollisionShape> shapes_;
};

}  // namespace crease::robot
