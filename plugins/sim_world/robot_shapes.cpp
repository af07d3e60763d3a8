#include "plugins/sim_world/robot_shapes.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"

namespace crease::world {
namespace {

void to_quat(const Pose& p, double q[4]) {
  // Shepperd's method on the row-major rotation.
  const double* r = p.r;
  const double tr = r[0] + r[4] + r[8];
  if (tr > 0) {
    const double s = 2.0 * std::sqrt(tr + 1.0);
    q[0] = 0.25 * s;
    q[1] = (r[7] - r[5]) / s;
    q[2] = (r[2] - r[6]) / s;
    q[3] = (r[3] - r[1]) / s;
  } else if (r[0] > r[4] && r[0] > r[8]) {
    const double s = 2.0 * std::sqrt(1.0 + r[0] - r[4] - r[8]);
    q[0] = (r[7] - r[5]) / s;
    q[1] = 0.25 * s;
    q[2] = (r[1] + r[3]) / s;
    q[3] = (r[2] + r[6]) / s;
  } else if (r[4] > r[8]) {
    const double s = 2.0 * std::sqrt(1.0 + r[4] - r[0] - r[8]);
    q[0] = (r[2] - r[6]) / s;
    q[1] = (r[1] + r[3]) / s;
    q[2] = 0.25 * s;
    q[3] = (r[5] + r[7]) / s;
  } else {
    const double s = 2.0 * std::sqrt(1.0 + r[8] - r[0] - r[4]);
    q[0] = (r[3] - r[1]) / s;
    q[1] = (r[2] + r[6]) / s;
    q[2] = (r[5] + r[7]) / s;
    q[3] = 0.25 * s;
  }
}

void from_quat(const double q[4], double r[9]) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  r[0] = 1 - 2 * (y * y + z * z);
  r[1] = 2 * (x * y - w * z);
  r[2] = 2 * (x * z + w * y);
  r[3] = 2 * (x * y + w * z);
  r[4] = 1 - 2 * (x * x + z * z);
  r[5] = 2 * (y * z - w * x);
  r[6] = 2 * (x * z - w * y);
  r[7] = 2 * (y * z + w * x);
  r[8] = 1 - 2 * (x * x + y * y);
}


}  // namespace

Pose WorldShape::pose_at(double a) const noexcept {
  if (a <= 0) return pose0;
  if (a >= 1) return pose1;
  Pose p;
  p.t = pose0.t + a * (pose1.t - pose0.t);
  const double d = quat0[0] * quat1[0] + quat0[1] * quat1[1] + quat0[2] * quat1[2] + quat0[3] * quat1[3];
  const double s = d < 0 ? -1.0 : 1.0;
  double q[4], n = 0;
  for (int k = 0; k < 4; ++k) {
    q[k] = (1 - a) * quat0[k] + a * s * quat1[k];
    n += q[k] * q[k];
  }
  n = 1.0 / std::sqrt(n);
  for (double& c : q) c *= n;
  from_quat(q, p.r);
  return p;
}

std::vector<WorldShape> build_robot_shapes(const robot::RobotModel& model,
                                           const std::array<const SideKinematics*, robot::kSides>& kin,
                                           const WorldDraws& draws, const WorldParams& params) {
  std::vector<WorldShape> out;
  const robot::RobotParams& rp = model.params();
  for (const robot::CollisionShape& c : model.collision_shapes()) {
    WorldShape s;
    int side = -1, link = -1;
    for (int k = 0; k < robot::kSides && link < 0; ++k) {
      link = kin[k]->link_index(c.link);
      side = k;
    }
    if (link < 0) throw ConfigError(model.urdf_file() + ": link '" + c.link + "': collision shape on no side's tree");
    s.side = side;
    s.link = link;
    s.body = kin[side]->body_of(link);
    s.link_from_shape = c.link_from_shape;
    switch (c.kind) {
      case robot::ShapeKind::sphere:
        s.geom = {GeomKind::sphere, 1000.0 * c.radius_m, 0.0, {}};
        break;
      case robot::ShapeKind::capsule:
        s.geom = {GeomKind::capsule, 1000.0 * c.radius_m, 500.0 * c.length_m, {}};
        break;
      case robot::ShapeKind::cylinder:
        s.geom = {GeomKind::cylinder, 1000.0 * c.radius_m, 500.0 * c.length_m, {}};
        break;
      case robot::ShapeKind::box:
        s.geom = {GeomKind::box, 0.0, 0.0,
                  {1000.0 * c.half_extents_m[0], 1000.0 * c.half_extents_m[1], 1000.0 * c.half_extents_m[2]}};
        break;
    }
    const robot::SideParams& sp = rp.sides[side];
    const std::string& material = c.surface == robot::Surface::cover ? sp.cover : sp.shell;
    const auto mu = draws.material_friction.find(material);
    s.friction = mu != draws.material_friction.end() ? mu->second : c.friction;
    const auto k = params.contact_stiffness_n_per_mm3.find(material);
    if (k == params.contact_stiffness_n_per_mm3.end() || !(k->second > 0)) {
      throw ConfigError(rp.file + ": material '" + material + "': the world needs its contact stiffness (> 0)");
    }
    s.stiffness_n_per_mm3 = k->second;
    s.compliant = kin[side]->moved_by_hand(link);
    const std::string local = c.link.substr(sp.prefix.size());
    s.role = s.compliant ? ShapeRole::finger : ShapeRole::arm;
    if (local == "forearm" || local == "wrist") s.role = ShapeRole::hand;
    if (local == "palm") s.role = ShapeRole::palm;
    for (int f = 0; f < robot::kFingertips; ++f) {
      const std::string tip(robot::kFingertipNames[f]);
      if (local.rfind(tip, 0) == 0) s.finger = f;
      if (local == tip + "pad") s.role = ShapeRole::pad;
      if (local == tip + "back") s.role = ShapeRole::back;
      if (local == tip + "distal") s.role = ShapeRole::fingertip;
      if (local == tip + "pad" || local == tip + "back" || local == tip + "distal") s.fingertip = f;
    }
    out.push_back(s);
  }
  advance_shape_poses_rt(out, kin, true);
  return out;
}

void advance_shape_poses_rt(std::vector<WorldShape>& shapes, const std::array<const SideKinematics*, robot::kSides>& kin,
                            bool first) noexcept {
  for (WorldShape& s : shapes) {
    const Pose p = kin[s.side]->compose(s.link, s.link_from_shape);
    if (first) {
      s.pose0 = p;
      to_quat(p, s.quat0);
    } else {
      s.pose0 = s.pose1;
      for (int k = 0; k < 4; ++k) s.quat0[k] = s.quat1[k];
    }
    s.pose1 = p;
    to_quat(p, s.quat1);
  }
}

// The port's enums are the world's, value for value.
static_assert(int(WorldShapes::Kind::sphere) == int(GeomKind::sphere) &&
              int(WorldShapes::Kind::capsule) == int(GeomKind::capsule) &&
              int(WorldShapes::Kind::cylinder) == int(GeomKind::cylinder) &&
              int(WorldShapes::Kind::box) == int(GeomKind::box));
static_assert(int(WorldShapes::Role::pad) == int(ShapeRole::pad) &&
              int(WorldShapes::Role::back) == int(ShapeRole::back) &&
              int(WorldShapes::Role::fingertip) == int(ShapeRole::fingertip) &&
              int(WorldShapes::Role::finger) == int(ShapeRole::finger) &&
              int(WorldShapes::Role::palm) == int(ShapeRole::palm) &&
              int(WorldShapes::Role::hand) == int(ShapeRole::hand) &&
              int(WorldShapes::Role::arm) == int(ShapeRole::arm));

void export_shapes_rt(const std::vector<WorldShape>& shapes, WorldShapes& out) noexcept {
  const std::size_t n = std::min<std::size_t>(shapes.size(), WorldShapes::kCapacity);
  out.count = static_cast<std::uint32_t>(n);
  for (std::size_t i = 0; i < n; ++i) {
    const WorldShape& s = shapes[i];
    WorldShapes::Shape& o = out.shapes[i];
    o.kind = static_cast<WorldShapes::Kind>(s.geom.kind);
    o.role = static_cast<WorldShapes::Role>(s.role);
    o.side = static_cast<std::uint8_t>(s.side);
    o.radius_mm = static_cast<float>(s.geom.radius_mm);
    o.half_length_mm = static_cast<float>(s.geom.half_length_mm);
    o.half_mm[0] = static_cast<float>(s.geom.half_mm.x);
    o.half_mm[1] = static_cast<float>(s.geom.half_mm.y);
    o.half_mm[2] = static_cast<float>(s.geom.half_mm.z);
    o.position_mm[0] = static_cast<float>(s.pose1.t.x);
    o.position_mm[1] = static_cast<float>(s.pose1.t.y);
    o.position_mm[2] = static_cast<float>(s.pose1.t.z);
    for (int k = 0; k < 9; ++k) o.rotation[k] = static_cast<float>(s.pose1.r[k]);
  }
}

}  // namespace crease::world
