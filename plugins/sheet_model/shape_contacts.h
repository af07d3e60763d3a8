// The node-against-rigid-shape contacts active in a frame, as arrays (padded to whole groups
// of 8) and their solve, every substep: push the node out to half the thickness along the
// shape's normal, then Coulomb friction on the substep's tangential move (static while the
// slide stays within friction x penetration, else shortened by that much).
// With AVX-512 (runtime check) 8 contacts are solved at once through gathers and scatters
// when no node has two contacts (they would collide within a group); else one by one. The
// two differ only by rounding (fused multiply-adds).
// Configure-time: reserve(). RT: everything else (no allocation).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "vec3.h"

namespace crease::sheet {

class ShapeContacts {
 public:
  // Room for `capacity` contacts (allocates).
  void reserve(int capacity);
  [[nodiscard]] int capacity() const noexcept { return static_cast<int>(node_.size()) - kGroup; }

  void clear() noexcept;
  // Appends a contact: nodes pushed in increasing order let the groups run (see above).
  // Returns false (nothing stored) when full.
  bool push(std::int32_t node, Vec3 normal, double offset_mm) noexcept;
  [[nodiscard]] int size() const noexcept { return n_; }

  // x: positions (moved), prev: positions at the substep's start, w: inverse masses (0:
  // pinned, left alone). half_thickness_mm: the sheet's surface offset from its mid-plane.
  void solve_rt(std::span<Vec3> x, std::span<const Vec3> prev, std::span<const double> w,
                double half_thickness_mm, double friction) const noexcept;

  // One by one even when the CPU has AVX-512 (tests compare the two).
  void force_scalar(bool on) noexcept { use_simd_ = has_simd_ && !on; }

 private:
  static constexpr int kGroup = 8;
  std::vector<std::int32_t> node_;
  std::vector<double> nx_, ny_, nz_, off_;  // normal (unit), surface: dot(normal, y) = off
  int n_ = 0;
  std::int32_t last_node_ = -1;
  bool increasing_ = true;  // every node pushed after a smaller one: no node twice
  bool has_simd_ = false, use_simd_ = false;
};

}  // namespace crease::sheet
