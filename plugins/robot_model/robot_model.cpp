#include "plugins/robot_model/robot_model.h"

#include <kdl_parser/kdl_parser.hpp>
#include <urdf_model/joint.h>
#include <urdf_model/model.h>

#include <cmath>
#include <string_view>

#include "core/errors.h"

namespace crease::robot {
namespace {

constexpr double kPi = 3.14159265358979323846;

KDL::Frame to_kdl(const urdf::Pose& p) {
  return KDL::Frame(KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
                    KDL::Vector(p.position.x, p.position.y, p.position.z));
}

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.size() >= prefix.size() && s.substr(0, prefix.size()) == prefix;
}

// The side whose prefix NAME starts with, or -1.
int side_of(const RobotParams& p, std::string_view name) {
  for (int s = 0; s < kSides; ++s) {
    if (starts_with(name, p.sides[s].prefix)) return s;
  }
  return -1;
}

std::string side_key(int s) { return "sides." + std::string(kSideNames[s]); }

// The arm's mounting from the YAML replaces the URDF's nominal world -> base joint.
KDL::Frame apply_mount(urdf::ModelInterface& model, const UrdfSource& src, const RobotParams& p, int s) {
  const SideParams& sp = p.sides[s];
  const std::string name = sp.prefix + "mount";
  const auto it = model.joints_.find(name);
  if (it == model.joints_.end()) {
    src.fail("joint", name, "missing: it mounts the " + std::string(kSideNames[s]) + " arm (" +
                                p.file + ": " + side_key(s) + ".mount)");
  }
  urdf::Joint& j = *it->second;
  if (j.type != urdf::Joint::FIXED || j.parent_link_name != kWorldLink) {
    src.fail("joint", name, "must be a fixed joint with parent link '" + std::string(kWorldLink) + "'");
  }
  urdf::Pose& o = j.parent_to_joint_origin_transform;
  o.position = urdf::Vector3(sp.mount.xyz_mm[0] / 1000.0, sp.mount.xyz_mm[1] / 1000.0,
                             sp.mount.xyz_mm[2] / 1000.0);
  o.rotation.setFromRPY(sp.mount.rpy_deg[0] * kPi / 180.0, sp.mount.rpy_deg[1] * kPi / 180.0,
                        sp.mount.rpy_deg[2] * kPi / 180.0);
  return to_kdl(o);
}

// An actuated joint: revolute, with limits, no mimic.
JointInfo actuated_joint(const urdf::ModelInterface& model, const UrdfSource& src,
                         const std::string& name, const char* role) {
  const auto j = model.getJoint(name);
  if (!j) src.fail("joint", name, std::string("missing: one of the ") + role);
  if (j->type != urdf::Joint::REVOLUTE) src.fail("joint", name, "must be revolute (with limits)");
  if (j->mimic) src.fail("joint", name, std::string("one of the ") + role + " cannot be a <mimic>");
  const urdf::JointLimits& l = *j->limits;  // urdfdom refuses a revolute joint without limits
  if (!(std::isfinite(l.lower) && std::isfinite(l.upper) && l.lower < l.upper)) {
    src.fail_at_child("joint", name, "limit", 0, "lower must be below upper");
  }
  if (!(std::isfinite(l.velocity) && l.velocity > 0)) {
    src.fail_at_child("joint", name, "limit", 0, "velocity must be > 0");
  }
  return JointInfo{name, l.lower, l.upper, l.velocity, l.effort};
}

}  // namespace

RobotModel RobotModel::load(const std::string& yaml_path) {
  RobotModel m;
  m.params_ = load_robot_params(yaml_path);
  UrdfDocument doc = read_urdf(m.params_.urdf_path);
  m.source_ = std::move(doc.source);
  urdf::ModelInterface& model = *doc.model;
  const UrdfSource& src = m.source_;
  const RobotParams& p = m.params_;

  const auto root = model.getRoot();
  if (!root || root->name != kWorldLink) {
    src.fail("link", root ? root->name : "", "the root link must be '" + std::string(kWorldLink) +
                                                  "' (z up, origin on the table surface)");
  }
  for (int s = 0; s < kSides; ++s) m.sides_[s].mount = apply_mount(model, src, p, s);
  if (!kdl_parser::treeFromUrdfModel(model, m.tree_)) {
    throw ConfigError(src.file() + ": kdl_parser could not build a kinematic tree");
  }

  for (int s = 0; s < kSides; ++s) {
    SideModel& side = m.sides_[s];
    const std::string& prefix = p.sides[s].prefix;
    for (int i = 0; i < kArmJoints; ++i) {
      side.arm.push_back(actuated_joint(model, src, prefix + std::string(kArmJointNames[i]),
                                        "7 arm joints S1 S2 S3 E1 E2 W1 W2"));
      side.sources[side.arm.back().name] = JointSource{JointSource::arm, i, 1.0, 0.0};
    }
    for (int i = 0; i < kHandJoints; ++i) {
      side.hand.push_back(actuated_joint(model, src, prefix + std::string(kHandJointNames[i]),
                                         "20 hand joints of drivers/README.md section 3"));
      side.sources[side.hand.back().name] = JointSource{JointSource::hand, i, 1.0, 0.0};
    }
  }
  // Every other movable joint follows a hand joint of its side.
  for (const auto& e : src.elements()) {
    if (e.kind != "joint") continue;
    const auto j = model.getJoint(e.name);
    if (!j || j->type == urdf::Joint::FIXED) continue;
    const int s = side_of(p, e.name);
    if (s < 0) src.fail("joint", e.name, "a movable joint of neither side (no side's prefix)");
    SideModel& side = m.sides_[s];
    if (side.sources.count(e.name)) continue;
    int master = -1;
    for (int i = 0; j->mimic && i < kHandJoints; ++i) {
      if (side.hand[i].name == j->mimic->joint_name) master = i;
    }
    if (master < 0) {
      src.fail("joint", e.name,
               "neither an arm joint, a hand joint, nor a <mimic> of one of its side's hand joints");
    }
    const MimicJoint mj{e.name, master, j->mimic->multiplier, j->mimic->offset};
    side.mimics.push_back(mj);
    side.sources[e.name] = JointSource{JointSource::hand, mj.master, mj.multiplier, mj.offset};
  }

  for (int s = 0; s < kSides; ++s) {
    for (int f = 0; f < kToolFrames; ++f) {
      m.sides_[s].tools.push_back(
          m.make_chain(static_cast<Side>(s), p.sides[s].prefix + std::string(kToolFrameLinks[f])));
    }
  }

  for (const auto& e : src.elements()) {
    if (e.kind != "link") continue;
    const auto link = model.getLink(e.name);
    if (!link) continue;
    std::vector<CollisionShape> shapes = collision_shapes_of(*link, src);
    if (shapes.empty()) continue;
    const int s = side_of(p, e.name);
    if (s < 0) src.fail("link", e.name, "collision shapes on a link of neither side (no side's prefix)");
    for (auto& shape : shapes) {
      shape.friction = shape.surface == Surface::cover ? p.sides[s].cover_friction
                                                       : p.sides[s].shell_friction;
      m.shapes_.push_back(std::move(shape));
    }
  }
  return m;
}

std::vector<CollisionShape> RobotModel::shapes_of(const std::string& link) const {
  std::vector<CollisionShape> out;
  for (const auto& s : shapes_) {
    if (s.link == link) out.push_back(s);
  }
  return out;
}

ToolChain RobotModel::make_chain(Side s, const std::string& link) const {
  const std::string side_name(kSideNames[index(s)]);
  if (!starts_with(link, params_.sides[index(s)].prefix)) {
    source_.fail("link", link, "not a link of the " + side_name + " side");
  }
  KDL::Chain chain;
  if (tree_.getSegments().count(link) == 0 || !tree_.getChain(std::string(kWorldLink), link, chain)) {
    source_.fail("link", link, "missing: a frame of the " + side_name + " side the kinematics needs");
  }
  const SideModel& side = sides_[index(s)];
  std::vector<JointSource> sources;
  for (const auto& seg : chain.segments) {
    const KDL::Joint& j = seg.getJoint();
    if (j.getType() == KDL::Joint::None) continue;
    const auto it = side.sources.find(j.getName());
    if (it == side.sources.end()) {
      source_.fail("joint", j.getName(), "on the way to " + link + " but not a joint of the " +
                                             side_name + " side");
    }
    sources.push_back(it->second);
  }
  return ToolChain(link, chain, std::move(sources));
}

}  // namespace crease::robot
