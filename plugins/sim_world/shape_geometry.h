// The robot's collision shapes in the world's units (mm), posed rigidly, and the few queries
// the world's contacts need: the signed distance of a point with the closest surface point and
// its outward normal, the closest point of the shape's core (what a sheet patch is pulled
// under, see finger_contacts.h), the lowest point (against the table) and a bounding box.
// Shapes as plugins/robot_model/collision_shapes.h: sphere; capsule and cylinder along the
// shape's z, centred; box centred, its edges rounded by its smallest half extent (the pads'
// 2 mm boxes by 1 mm, the palm's by 12 mm) so that its surface normal turns smoothly around an
// edge as a capsule's does. RT: every function here is inline arithmetic.
#pragma once

#include <algorithm>
#include <cmath>

#include "plugins/sheet_model/vec3.h"

namespace crease::world {

using sheet::Vec3;

// x_world = R x_shape + t; R row-major.
struct Pose {
  double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  Vec3 t;

  [[nodiscard]] Vec3 apply(Vec3 p) const noexcept {
    return {r[0] * p.x + r[1] * p.y + r[2] * p.z + t.x, r[3] * p.x + r[4] * p.y + r[5] * p.z + t.y,
            r[6] * p.x + r[7] * p.y + r[8] * p.z + t.z};
  }
  [[nodiscard]] Vec3 rotate(Vec3 p) const noexcept {
    return {r[0] * p.x + r[1] * p.y + r[2] * p.z, r[3] * p.x + r[4] * p.y + r[5] * p.z,
            r[6] * p.x + r[7] * p.y + r[8] * p.z};
  }
  [[nodiscard]] Vec3 inverse_apply(Vec3 p) const noexcept {  // R^T (p - t)
    const Vec3 d = p - t;
    return {r[0] * d.x + r[3] * d.y + r[6] * d.z, r[1] * d.x + r[4] * d.y + r[7] * d.z,
            r[2] * d.x + r[5] * d.y + r[8] * d.z};
  }
  [[nodiscard]] Vec3 inverse_rotate(Vec3 d) const noexcept {  // R^T d
    return {r[0] * d.x + r[3] * d.y + r[6] * d.z, r[1] * d.x + r[4] * d.y + r[7] * d.z,
            r[2] * d.x + r[5] * d.y + r[8] * d.z};
  }
  [[nodiscard]] Vec3 axis(int c) const noexcept { return {r[c], r[3 + c], r[6 + c]}; }
};

enum class GeomKind : unsigned char { sphere, capsule, cylinder, box };

struct Geom {
  GeomKind kind = GeomKind::sphere;
  double radius_mm = 0;       // sphere, capsule, cylinder
  double half_length_mm = 0;  // capsule: half the distance between the cap centres; cylinder: half its length
  Vec3 half_mm;               // box half extents
};

struct SurfacePoint {
  double distance_mm = 0;  // signed: < 0 inside
  Vec3 point;              // closest point on the surface, world
  Vec3 normal;             // outward unit normal there
};

namespace detail {

inline double clampd(double v, double lo, double hi) noexcept { return std::min(std::max(v, lo), hi); }

// Any unit vector perpendicular to the shape's z (a capsule point on its axis: no direction).
inline Vec3 fallback_normal(const Pose& pose) noexcept { return pose.axis(0); }

}  // namespace detail

// Signed distance of point l from the shape's surface, all in the shape's frame (point and
// normal too). RT.
inline SurfacePoint closest_surface_local(const Geom& g, Vec3 l) noexcept {
  SurfacePoint out;
  Vec3 n_local, s_local;
  switch (g.kind) {
    case GeomKind::sphere:
    case GeomKind::capsule: {
      const double h = g.kind == GeomKind::capsule ? g.half_length_mm : 0.0;
      const Vec3 c{0, 0, detail::clampd(l.z, -h, h)};
      const Vec3 d = l - c;
      const double len = sheet::norm(d);
      n_local = len > 1e-12 ? (1.0 / len) * d : Vec3{1, 0, 0};
      s_local = c + g.radius_mm * n_local;
      out.distance_mm = len - g.radius_mm;
      break;
    }
    case GeomKind::cylinder: {
      const double rho = std::hypot(l.x, l.y);
      const Vec3 radial = rho > 1e-12 ? Vec3{l.x / rho, l.y / rho, 0} : Vec3{1, 0, 0};
      const double dr = rho - g.radius_mm, dz = std::fabs(l.z) - g.half_length_mm;
      const double sz = l.z >= 0 ? 1.0 : -1.0;
      if (dr > 0 && dz > 0) {  // beyond the rim
        const Vec3 rim = g.radius_mm * radial + Vec3{0, 0, sz * g.half_length_mm};
        const Vec3 d = l - rim;
        const double len = sheet::norm(d);
        n_local = (1.0 / len) * d;
        s_local = rim;
        out.distance_mm = len;
      } else if (dz > dr) {  // nearer the cap (outside it, or inside with the cap the nearest face)
        n_local = {0, 0, sz};
        s_local = {l.x, l.y, sz * g.half_length_mm};
        out.distance_mm = dz;
      } else {  // nearer the side
        n_local = radial;
        s_local = {g.radius_mm * radial.x, g.radius_mm * radial.y, detail::clampd(l.z, -g.half_length_mm, g.half_length_mm)};
        out.distance_mm = dr;
      }
      break;
    }
    case GeomKind::box: {  // rounded: its core (box shrunk by r) grown by r
      const double r = std::min({g.half_mm.x, g.half_mm.y, g.half_mm.z});
      const Vec3 c{detail::clampd(l.x, -(g.half_mm.x - r), g.half_mm.x - r),
                   detail::clampd(l.y, -(g.half_mm.y - r), g.half_mm.y - r),
                   detail::clampd(l.z, -(g.half_mm.z - r), g.half_mm.z - r)};
      const Vec3 d = l - c;
      const double len = sheet::norm(d);
      if (len > 1e-12) {
        n_local = (1.0 / len) * d;
      } else {  // on the core: out through the thin axis
        const Vec3& h = g.half_mm;
        n_local = h.z <= h.x && h.z <= h.y ? Vec3{0, 0, l.z >= 0 ? 1.0 : -1.0}
                  : h.y <= h.x            ? Vec3{0, l.y >= 0 ? 1.0 : -1.0, 0}
                                          : Vec3{l.x >= 0 ? 1.0 : -1.0, 0, 0};
      }
      s_local = c + r * n_local;
      out.distance_mm = len - r;
      break;
    }
  }
  out.point = s_local;
  out.normal = n_local;
  return out;
}

// Signed distance of world point p from the shape's surface. RT.
inline SurfacePoint closest_surface(const Geom& g, const Pose& pose, Vec3 p) noexcept {
  SurfacePoint out = closest_surface_local(g, pose.inverse_apply(p));
  out.point = pose.apply(out.point);
  out.normal = pose.rotate(out.normal);
  return out;
}

// The point of the shape's core nearest to world point p: the centre of a sphere, the nearest
// point of a capsule's or cylinder's axis segment, the nearest point of a box shrunk by its
// smallest half extent on every axis. The shape is that core grown (exactly for a sphere or a
// capsule), so the deepest point of a flat patch under the shape lies below its core. RT.
inline Vec3 closest_core_local(const Geom& g,
                               Vec3 l) noexcept {  // l and the result in the shape's frame
  Vec3 c;
  switch (g.kind) {
    case GeomKind::sphere:
      break;
    case GeomKind::capsule:
    case GeomKind::cylinder:
      c.z = detail::clampd(l.z, -g.half_length_mm, g.half_length_mm);
      break;
    case GeomKind::box: {
      const double m = std::min({g.half_mm.x, g.half_mm.y, g.half_mm.z});
      c = {detail::clampd(l.x, -(g.half_mm.x - m), g.half_mm.x - m), detail::clampd(l.y, -(g.half_mm.y - m), g.half_mm.y - m),
           detail::clampd(l.z, -(g.half_mm.z - m), g.half_mm.z - m)};
      break;
    }
  }
  return c;
}
inline Vec3 closest_core(const Geom& g, const Pose& pose, Vec3 p) noexcept {
  return pose.apply(closest_core_local(g, pose.inverse_apply(p)));
}

// How far the shape reaches beyond its core (closest_core): |p - core| minus it is a lower bound
// on p's distance from the shape, exact for a sphere, a capsule and a (rounded) box; a cylinder
// lies within the capsule of its radius. mm. RT.
inline double core_grow(const Geom& g) noexcept {
  return g.kind == GeomKind::box ? std::min({g.half_mm.x, g.half_mm.y, g.half_mm.z}) : g.radius_mm;
}

// The shape's lowest world point (smallest z) and the shape's extent in world x, y, z. RT.
inline Vec3 lowest_point(const Geom& g, const Pose& pose) noexcept {
  // The local direction of world -z is the third row of R, negated.
  const Vec3 down{-pose.r[6], -pose.r[7], -pose.r[8]};
  Vec3 l;
  switch (g.kind) {
    case GeomKind::sphere:
      l = g.radius_mm * down;
      break;
    case GeomKind::capsule:
      l = Vec3{0, 0, down.z >= 0 ? g.half_length_mm : -g.half_length_mm} + g.radius_mm * down;
      break;
    case GeomKind::cylinder: {
      const double rho = std::hypot(down.x, down.y);
      l = {rho > 1e-12 ? g.radius_mm * down.x / rho : 0.0, rho > 1e-12 ? g.radius_mm * down.y / rho : 0.0,
           down.z >= 0 ? g.half_length_mm : -g.half_length_mm};
      break;
    }
    case GeomKind::box: {
      const double r = std::min({g.half_mm.x, g.half_mm.y, g.half_mm.z});
      l = Vec3{down.x >= 0 ? g.half_mm.x - r : r - g.half_mm.x, down.y >= 0 ? g.half_mm.y - r : r - g.half_mm.y,
               down.z >= 0 ? g.half_mm.z - r : r - g.half_mm.z} +
          r * down;
      break;
    }
  }
  return pose.apply(l);
}

// How far the shape reaches from its pose's origin in any direction (mm): the radius of a
// sphere about pose.t that holds it, whatever its orientation. RT.
inline double bounding_radius(const Geom& g) noexcept {
  switch (g.kind) {
    case GeomKind::sphere:
      return g.radius_mm;
    case GeomKind::capsule:
      return g.radius_mm + g.half_length_mm;
    case GeomKind::cylinder:
      return std::hypot(g.radius_mm, g.half_length_mm);
    case GeomKind::box:
      return std::sqrt(g.half_mm.x * g.half_mm.x + g.half_mm.y * g.half_mm.y +
                       g.half_mm.z * g.half_mm.z);
  }
  return 0;
}

// The nearest points of two shapes' cores (closest_core), by alternating projections from a's
// centre, ITERATIONS rounds: exact for two spheres, converging for capsules and boxes' cores
// (convex). The shapes overlap by core_grow(a) + core_grow(b) - |cb - ca|. RT.
inline void closest_cores(const Geom& a, const Pose& pa, const Geom& b, const Pose& pb, Vec3& ca,
                          Vec3& cb, int iterations = 4) noexcept {
  ca = pa.t;
  for (int it = 0; it < iterations; ++it) {
    cb = closest_core(b, pb, ca);
    ca = closest_core(a, pa, cb);
  }
}

// Half the extent of the shape's bounding box along world axis a (0 x, 1 y, 2 z), from its
// centre pose.t. RT.
inline double half_extent(const Geom& g, const Pose& pose, int a) noexcept {
  const double* row = &pose.r[3 * a];  // world axis a in shape coordinates
  switch (g.kind) {
    case GeomKind::sphere:
      return g.radius_mm;
    case GeomKind::capsule:
      return g.radius_mm + g.half_length_mm * std::fabs(row[2]);
    case GeomKind::cylinder:
      return g.radius_mm * std::sqrt(std::max(0.0, 1.0 - row[2] * row[2])) + g.half_length_mm * std::fabs(row[2]);
    case GeomKind::box:
      return g.half_mm.x * std::fabs(row[0]) + g.half_mm.y * std::fabs(row[1]) + g.half_mm.z * std::fabs(row[2]);
  }
  return 0;
}

}  // namespace crease::world
