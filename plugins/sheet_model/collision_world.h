// Rigid obstacles of the sheet (the table, fingertips, tools) as ODE collision geoms.
// Only ODE's collision detection is used (dCollide on space-less geoms): the sheet
// solvers turn the returned contacts into position constraints with friction.
// Configure-time: constructor and add_*; RT: set_pose, query_rt.
#pragma once

#include <cstdint>
#include <vector>

#include "vec3.h"

struct dxGeom;

namespace crease::sheet {

// One contact of a probe sphere against a shape: the shape's surface there is the plane
// {y : dot(normal, y) = offset_mm}, normal pointing out of the shape.
struct ShapeContact {
  Vec3 normal;
  double offset_mm = 0;
  int shape = -1;
};

class CollisionWorld {
 public:
  static constexpr int kMaxShapes = 64;

  CollisionWorld();  // calls dInitODE2 once per process
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  // Each returns the shape id. Sizes in mm; the table is the plane z = height_mm.
  int add_table(double height_mm = 0.0);
  int add_box(Vec3 size_mm, Vec3 center_mm);
  int add_sphere(double radius_mm, Vec3 center_mm);
  int add_capsule(double radius_mm, double length_mm, Vec3 center_mm);  // axis along z

  // Moves a placeable shape; rotation is row-major 3x3 (nullptr keeps it). RT.
  void set_pose(int shape, Vec3 center_mm, const double* rotation_row_major = nullptr) noexcept;

  // Contacts of a sphere of radius_mm at p with every shape; writes up to `capacity`.
  // Returns the number written. RT.
  int query_rt(Vec3 p, double radius_mm, ShapeContact* out, int capacity) const noexcept;

  [[nodiscard]] int shape_count() const noexcept { return static_cast<int>(geoms_.size()); }
  // Incremented by every add_* and set_pose (contact caches compare it).
  [[nodiscard]] std::uint64_t version() const noexcept { return version_; }

 private:
  int add_geom(dxGeom* g);
  std::vector<dxGeom*> geoms_;
  dxGeom* probe_ = nullptr;
  std::uint64_t version_ = 0;
};

}  // namespace crease::sheet
