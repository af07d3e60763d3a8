#include "plugins/sim_world/side_kinematics.h"

#include <kdl/tree.hpp>

#include <map>
#include <utility>

#include "core/errors.h"

namespace crease::world {
namespace {

Pose to_pose(const KDL::Frame& f) {
  Pose p;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p.r[3 * i + j] = f.M(i, j);
  p.t = {1000.0 * f.p.x(), 1000.0 * f.p.y(), 1000.0 * f.p.z()};
  return p;
}

Vec3 mm(const KDL::Vector& v) { return {1000.0 * v.x(), 1000.0 * v.y(), 1000.0 * v.z()}; }
Vec3 unit(const KDL::Vector& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

SideKinematics::SideKinematics(const robot::RobotModel& model, robot::Side side) {
  const std::string& prefix = model.params().side(side).prefix;
  std::map<std::string, Source> sources;
  const auto& arm = model.arm_joints(side);
  for (int i = 0; i < static_cast<int>(arm.size()); ++i) sources[arm[i].name] = {Source::arm, i, 1.0, 0.0};
  const auto& hand = model.hand_joints(side);
  for (int i = 0; i < static_cast<int>(hand.size()); ++i) sources[hand[i].name] = {Source::hand, i, 1.0, 0.0};
  for (const auto& m : model.hand_mimics(side)) sources[m.name] = {Source::hand, m.master, m.multiplier, m.offset};

  const KDL::Tree& tree = model.tree();
  const auto root = tree.getRootSegment();
  std::vector<std::pair<KDL::SegmentMap::const_iterator, int>> stack;
  for (const auto& child : GetTreeElementChildren(root->second)) {
    if (child->first.rfind(prefix, 0) == 0) stack.emplace_back(child, -1);
  }
  while (!stack.empty()) {
    const auto [it, parent] = stack.back();
    stack.pop_back();
    Seg s;
    s.name = it->first;
    s.segment = GetTreeElementSegment(it->second);
    s.parent = parent;
    const KDL::Joint& j = s.segment.getJoint();
    if (j.getType() != KDL::Joint::None) {
      const auto found = sources.find(j.getName());
      if (found == sources.end()) {
        throw ConfigError(model.urdf_file() + ": joint '" + j.getName() +
                          "': movable, but neither an arm joint, a hand joint nor a mimic of one");
      }
      s.source = found->second;
    }
    if (parent >= 0) {
      const Seg& p = seg_[parent];
      s.hand_anc = p.hand_anc;
      s.hand_anc_count = p.hand_anc_count;
    }
    const int index = static_cast<int>(seg_.size());
    s.body = s.source.kind != Source::none ? index : (parent >= 0 ? seg_[parent].body : -1);
    if (s.source.kind == Source::hand) {
      if (s.hand_anc_count >= kMaxAncestors) {
        throw ConfigError(model.urdf_file() + ": link '" + s.name + "': more than 12 hand joints above it");
      }
      s.hand_anc[s.hand_anc_count++] = index;
    }
    seg_.push_back(std::move(s));
    for (const auto& child : GetTreeElementChildren(it->second)) stack.emplace_back(child, index);
  }
  frame_.assign(seg_.size(), KDL::Frame::Identity());
  pose_.assign(seg_.size(), Pose{});
  axis_.assign(seg_.size(), Vec3{});
  origin_.assign(seg_.size(), Vec3{});
  last_q_.assign(seg_.size(), 0.0);
  moved_.assign(seg_.size(), 1);
  posed_ = false;
}

void SideKinematics::update_rt(robot::ArmAngles arm, robot::HandAngles hand) noexcept {
  const KDL::Frame identity = KDL::Frame::Identity();
  for (std::size_t i = 0; i < seg_.size(); ++i) {
    const Seg& s = seg_[i];
    const KDL::Frame& base = s.parent >= 0 ? frame_[s.parent] : identity;
    double q = 0.0;
    if (s.source.kind == Source::arm) q = s.source.multiplier * arm[s.source.index] + s.source.offset;
    if (s.source.kind == Source::hand) q = s.source.multiplier * hand[s.source.index] + s.source.offset;
    const bool moved = !posed_ || q != last_q_[i] || (s.parent >= 0 && moved_[s.parent]);
    moved_[i] = moved ? 1 : 0;
    if (!moved) continue;
    last_q_[i] = q;
    frame_[i] = base * s.segment.pose(q);
    pose_[i] = to_pose(frame_[i]);
    if (s.source.kind != Source::none) {
      const KDL::Joint& j = s.segment.getJoint();
      axis_[i] = unit(base.M * j.JointAxis());
      origin_[i] = mm(base * j.JointOrigin());
    }
  }
  posed_ = true;
}

int SideKinematics::link_index(std::string_view name) const noexcept {
  for (std::size_t i = 0; i < seg_.size(); ++i)
    if (seg_[i].name == name) return static_cast<int>(i);
  return -1;
}

Pose SideKinematics::compose(int link, const KDL::Frame& link_from_x_m) const noexcept {
  return to_pose(frame_[link] * link_from_x_m);
}

void SideKinematics::add_hand_jacobian_transpose(int link, Vec3 p, Vec3 f,
                                                 std::span<double, robot::kHandJoints> g) const noexcept {
  const Seg& s = seg_[link];
  for (int k = 0; k < s.hand_anc_count; ++k) {
    const int a = s.hand_anc[k];
    const Source& src = seg_[a].source;
    g[src.index] += src.multiplier * sheet::dot(sheet::cross(axis_[a], p - origin_[a]), f);
  }
}

void SideKinematics::add_hand_wrench_transpose(int link, Vec3 f, Vec3 m,
                                               std::span<double, robot::kHandJoints> g) const noexcept {
  const Seg& s = seg_[link];
  for (int k = 0; k < s.hand_anc_count; ++k) {
    const int a = s.hand_anc[k];
    const Source& src = seg_[a].source;
    g[src.index] += src.multiplier * sheet::dot(axis_[a], m - sheet::cross(origin_[a], f));
  }
}

Vec3 SideKinematics::hand_jacobian_times(int link, Vec3 p, std::span<const double, robot::kHandJoints> dq) const noexcept {
  const Seg& s = seg_[link];
  Vec3 out;
  for (int k = 0; k < s.hand_anc_count; ++k) {
    const int a = s.hand_anc[k];
    const Source& src = seg_[a].source;
    out += (src.multiplier * dq[src.index]) * sheet::cross(axis_[a], p - origin_[a]);
  }
  return out;
}

}  // namespace crease::world
