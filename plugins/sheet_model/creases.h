// Crease lines in sheet coordinates and the test of which links cross them (seed 000 III).
#pragma once

#include <array>
#include <cstdint>

#include "vec3.h"

namespace crease::sheet {

struct CreaseLine {
  Vec2 a, b;  // segment end points, sheet mm
};

// True when the open segments p-q and a-b intersect properly (sheet coordinates).
// Touching at an end point counts as crossing only for the link (a link ending on the
// crease line is not cut; a crease ending inside a link's span is).
[[nodiscard]] inline bool segments_cross(Vec2 p, Vec2 q, Vec2 a, Vec2 b) noexcept {
  auto orient = [](Vec2 o, Vec2 s, Vec2 t) {
    return (s.u - o.u) * (t.v - o.v) - (s.v - o.v) * (t.u - o.u);
  };
  const double d1 = orient(a, b, p), d2 = orient(a, b, q);
  const double d3 = orient(p, q, a), d4 = orient(p, q, b);
  const double eps = 1e-9;
  const bool link_straddles = (d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps);
  const bool crease_reaches = (d3 >= -eps && d4 <= eps) || (d3 <= eps && d4 >= -eps);
  return link_straddles && crease_reaches;
}

// Fixed-capacity set of creases with stable ids (RT: add/remove never allocate).
class CreaseSet {
 public:
  static constexpr int kCapacity = 32;

  // Returns the new crease's id (>= 0) or -1 when full / not finite.
  int add(CreaseLine line) noexcept {
    if (!std::isfinite(line.a.u) || !std::isfinite(line.a.v) || !std::isfinite(line.b.u) ||
        !std::isfinite(line.b.v))
      return -1;
    for (int k = 0; k < kCapacity; ++k) {
      if (!used_[k]) {
        used_[k] = true;
        lines_[k] = line;
        ++count_;
        return k;
      }
    }
    return -1;
  }
  bool remove(int id) noexcept {
    if (id < 0 || id >= kCapacity || !used_[id]) return false;
    used_[id] = false;
    --count_;
    return true;
  }
  void clear() noexcept {
    used_.fill(false);
    count_ = 0;
  }
  [[nodiscard]] bool used(int id) const noexcept { return id >= 0 && id < kCapacity && used_[id]; }
  [[nodiscard]] const CreaseLine& line(int id) const noexcept { return lines_[id]; }
  [[nodiscard]] int count() const noexcept { return count_; }

 private:
  std::array<CreaseLine, kCapacity> lines_{};
  std::array<bool, kCapacity> used_{};
  int count_ = 0;
};

}  // namespace crease::sheet
