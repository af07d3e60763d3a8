#include "collision_world.h"

#include <ode/ode.h>

#include <mutex>

#include "core/assert.h"

namespace crease::sheet {
namespace {

void init_ode_once() {
  static std::once_flag once;
  std::call_once(once, [] { dInitODE2(0); });
}

}  // namespace

CollisionWorld::CollisionWorld() {
  init_ode_once();
  geoms_.reserve(kMaxShapes);
  probe_ = dCreateSphere(nullptr, 1.0);
}

CollisionWorld::~CollisionWorld() {
  for (dxGeom* g : geoms_) dGeomDestroy(g);
  dGeomDestroy(probe_);
}

int CollisionWorld::add_geom(dxGeom* g) {
  if (static_cast<int>(geoms_.size()) >= kMaxShapes) {
    dGeomDestroy(g);
    throw crease::ConfigError("sheet_model: collision shapes: more than 64");
  }
  geoms_.push_back(g);
  ++version_;
  return static_cast<int>(geoms_.size()) - 1;
}

int CollisionWorld::add_table(double height_mm) {
  return add_geom(dCreatePlane(nullptr, 0, 0, 1, height_mm));
}

int CollisionWorld::add_box(Vec3 s, Vec3 c) {
  crease::require_input(s.x > 0 && s.y > 0 && s.z > 0, "sheet_model: box size_mm: must be > 0");
  dxGeom* g = dCreateBox(nullptr, s.x, s.y, s.z);
  dGeomSetPosition(g, c.x, c.y, c.z);
  return add_geom(g);
}

int CollisionWorld::add_sphere(double r, Vec3 c) {
  crease::require_input(r > 0, "sheet_model: sphere radius_mm: must be > 0");
  dxGeom* g = dCreateSphere(nullptr, r);
  dGeomSetPosition(g, c.x, c.y, c.z);
  return add_geom(g);
}

int CollisionWorld::add_capsule(double r, double len, Vec3 c) {
  crease::require_input(r > 0 && len >= 0, "sheet_model: capsule radius_mm/length_mm: must be > 0");
  dxGeom* g = dCreateCapsule(nullptr, r, len);
  dGeomSetPosition(g, c.x, c.y, c.z);
  return add_geom(g);
}

void CollisionWorld::set_pose(int shape, Vec3 c, const double* rot) noexcept {
  if (shape < 0 || shape >= shape_count()) return;
  dxGeom* g = geoms_[shape];
  if (dGeomGetClass(g) == dPlaneClass) return;
  ++version_;
  dGeomSetPosition(g, c.x, c.y, c.z);
  if (rot != nullptr) {
    dMatrix3 m = {rot[0], rot[1], rot[2], 0, rot[3], rot[4], rot[5], 0, rot[6], rot[7], rot[8], 0};
    dGeomSetRotation(g, m);
  }
}

int CollisionWorld::query_rt(Vec3 p, double radius, ShapeContact* out, int capacity) const noexcept {
  dGeomSphereSetRadius(probe_, radius);
  dGeomSetPosition(probe_, p.x, p.y, p.z);
  int n = 0;
  for (int s = 0; s < shape_count() && n < capacity; ++s) {
    dContactGeom c[1];
    // o1 = probe: moving the probe along c.normal by c.depth separates them.
    if (dCollide(probe_, geoms_[s], 1, c, sizeof(dContactGeom)) < 1) continue;
    const Vec3 nrm{c[0].normal[0], c[0].normal[1], c[0].normal[2]};
    // Centre-to-surface distance along the normal is radius - depth.
    out[n].normal = nrm;
    out[n].offset_mm = dot(nrm, p) - (radius - c[0].depth);
    out[n].shape = s;
    ++n;
  }
  return n;
}

}  // namespace crease::sheet
