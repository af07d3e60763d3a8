// The once-per-frame test of layer-contact candidates (ContactSolver::select_rt), 8 at a
// time with AVX-512 gathers when the CPU has it (runtime check). A candidate (node p,
// triangle t with corners a, b, c and this frame's normal n = (b - a) x (c - a)) passes when
// |n|^2 > min_area2, ((p - a).n)^2 < reach^2 |n|^2 and the barycentric coordinates of p's
// projection are all >= -tol; it takes the side of t that p is on now. The scalar test is
// barycentric_inside(); the vector one differs only by rounding (fused multiply-adds).
// RT: no allocation.
#pragma once

#include <cstdint>

#include "vec3.h"

namespace crease::sheet {

struct LayerPair {
  std::int32_t node, tri;
  double side;  // +1 / -1: which side of the triangle the node stays on
};

// Barycentric coordinates of p's projection onto the plane of (a, b, c), from the signed
// areas: n = (b - a) x (c - a), nn = |n|^2 > 0. True when all are >= -tol.
bool barycentric_inside(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n, double nn,
                        double tol, double out[3]) noexcept;

[[nodiscard]] bool layer_select_simd_available() noexcept;

// Candidates cand[0, n) passing the test, with their side, written to out (room for n);
// returns how many. tri: corner indices (3 per triangle); tri_n: normals by triangle.
// simd: 8 at a time (only when layer_select_simd_available()).
int layer_select(const LayerPair* cand, int n, const std::int32_t* tri, const Vec3* x, const Vec3* tri_n,
                 double reach, double tol, double min_area2, LayerPair* out, bool simd) noexcept;

}  // namespace crease::sheet
