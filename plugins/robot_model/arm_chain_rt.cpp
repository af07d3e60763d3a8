#include "plugins/robot_model/arm_chain_rt.h"

#include <cmath>
#include <string>

#include "core/errors.h"

namespace crease::robot {
namespace {

Eigen::Matrix3d rotation(const KDL::Rotation& r) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = r(i, j);
  return m;
}
Eigen::Vector3d vector(const KDL::Vector& v) {
  return {v.x(), v.y(), v.z()};
}

// The rotation by angle q about the unit axis a (Rodrigues).
Eigen::Matrix3d about(const Eigen::Vector3d& a, double q) noexcept {
  const double s = std::sin(q), c = std::cos(q), t = 1.0 - c;
  Eigen::Matrix3d r;
  r << t * a.x() * a.x() + c, t * a.x() * a.y() - s * a.z(), t * a.x() * a.z() + s * a.y(),  //
      t * a.x() * a.y() + s * a.z(), t * a.y() * a.y() + c, t * a.y() * a.z() - s * a.x(),   //
      t * a.x() * a.z() - s * a.y(), t * a.y() * a.z() + s * a.x(), t * a.z() * a.z() + c;
  return r;
}

}  // namespace

ArmChainRt::ArmChainRt(const KDL::Chain& chain) {
  int joints = 0;
  for (const KDL::Segment& seg : chain.segments) {
    const KDL::Joint& j = seg.getJoint();
    Segment s;
    const KDL::Frame f0 = seg.pose(0.0);
    s.r0 = rotation(f0.M);
    s.p0 = vector(f0.p);
    if (j.getType() != KDL::Joint::None) {
      if (j.getType() != KDL::Joint::RotAxis && j.getType() != KDL::Joint::RotX &&
          j.getType() != KDL::Joint::RotY && j.getType() != KDL::Joint::RotZ)
        throw ConfigError("arm chain: joint '" + j.getName() + "' is not revolute");
      s.revolute = true;
      s.a = vector(j.JointAxis()).normalized();
      s.o = vector(j.JointOrigin());
      ++joints;
      // The same pose as KDL's at two angles, or this joint is one the form does not describe
      // (a scale or an offset on its angle).
      for (const double q : {0.7, -1.9}) {
        const KDL::Frame want = seg.pose(q);
        const Eigen::Matrix3d r = about(s.a, q);
        const Eigen::Matrix3d got_r = r * s.r0;
        const Eigen::Vector3d got_p = r * (s.p0 - s.o) + s.o;
        if ((got_r - rotation(want.M)).cwiseAbs().maxCoeff() > 1e-9 ||
            (got_p - vector(want.p)).norm() > 1e-9)
          throw ConfigError("arm chain: joint '" + j.getName() +
                            "' moves its segment in a way ArmChainRt does not take");
      }
    }
    segments_.push_back(s);
  }
  if (joints != kArmJoints)
    throw ConfigError("arm chain: " + std::to_string(joints) + " revolute joints, not " +
                      std::to_string(kArmJoints));
}

void ArmChainRt::pass(const std::array<double, kArmJoints>& q,
                      std::array<Eigen::Vector3d, kArmJoints>& axis,
                      std::array<Eigen::Vector3d, kArmJoints>& origin,
                      Eigen::Isometry3d& flange) const noexcept {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  int j = 0;
  for (const Segment& s : segments_) {
    if (!s.revolute) {
      p += r * s.p0;
      r = r * s.r0;
      continue;
    }
    axis[static_cast<std::size_t>(j)] = r * s.a;
    origin[static_cast<std::size_t>(j)] = p + r * s.o;
    const Eigen::Matrix3d rq =
        r * about(s.a, q[static_cast<std::size_t>(j)]);  // world <- turned parent
    p += rq * (s.p0 - s.o) + r * s.o;
    r = rq * s.r0;
    ++j;
  }
  flange.linear() = r;
  flange.translation() = p;
}

}  // namespace crease::robot
