#include "plugins/robot_model/collision_shapes.h"

#include <cmath>
#include <string_view>

namespace crease::robot {
namespace {

KDL::Frame to_kdl(const urdf::Pose& p) {
  return KDL::Frame(KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
                    KDL::Vector(p.position.x, p.position.y, p.position.z));
}

bool positive(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

std::vector<CollisionShape> collision_shapes_of(const urdf::Link& link, const UrdfSource& source) {
  std::vector<CollisionShape> out;
  int index = 0;
  for (const auto& c : link.collision_array) {
    const auto refuse = [&](const std::string& reason) {
      source.fail_at_child("link", link.name, "collision", index, reason);
    };
    if (!c || !c->geometry) refuse("a <collision> without geometry");
    constexpr std::string_view kCapsule = "_capsule";
    std::string_view surface = c->name;
    const bool capsule = surface.size() > kCapsule.size() &&
                         surface.substr(surface.size() - kCapsule.size()) == kCapsule;
    if (capsule) surface.remove_suffix(kCapsule.size());
    CollisionShape s;
    s.link = link.name;
    if (surface == "cover") s.surface = Surface::cover;
    else if (surface == "shell") s.surface = Surface::shell;
    else refuse("collision name '" + c->name + "': expected cover or shell, optionally + _capsule");
    s.link_from_shape = to_kdl(c->origin);
    const urdf::Geometry& g = *c->geometry;
    switch (g.type) {
      case urdf::Geometry::SPHERE:
        s.kind = ShapeKind::sphere;
        s.radius_m = static_cast<const urdf::Sphere&>(g).radius;
        if (!positive(s.radius_m)) refuse("a sphere's radius must be > 0");
        break;
      case urdf::Geometry::BOX: {
        const auto& d = static_cast<const urdf::Box&>(g).dim;
        s.kind = ShapeKind::box;
        s.half_extents_m = {d.x / 2, d.y / 2, d.z / 2};
        if (!positive(d.x) || !positive(d.y) || !positive(d.z)) refuse("a box's size must be > 0");
        break;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& cyl = static_cast<const urdf::Cylinder&>(g);
        s.kind = capsule ? ShapeKind::capsule : ShapeKind::cylinder;
        s.radius_m = cyl.radius;
        s.length_m = cyl.length;
        if (!positive(s.radius_m) || !positive(s.length_m)) {
          refuse("a cylinder's radius and length must be > 0");
        }
        break;
      }
      case urdf::Geometry::MESH:
        refuse("a mesh collision: use spheres, boxes, cylinders or capsules");
    }
    if (capsule && s.kind != ShapeKind::capsule) {
      refuse("collision name '" + c->name + "': only a <cylinder> can be a capsule");
    }
    out.push_back(std::move(s));
    ++index;
  }
  return out;
}

}  // namespace crease::robot
