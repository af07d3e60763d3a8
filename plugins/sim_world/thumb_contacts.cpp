#include "plugins/sim_world/thumb_contacts.h"

#include <cmath>

namespace crease::world {

void ThumbContacts::configure(std::span<const WorldShape> shapes, double contact_area_mm2) {
  shapes_ = shapes.data();
  for (auto& p : pairs_) p.clear();
  for (int a = 0; a < static_cast<int>(shapes.size()); ++a) {
    const WorldShape& sa = shapes[a];
    if (!sa.compliant || sa.finger != kThumb) continue;
    for (int b = 0; b < static_cast<int>(shapes.size()); ++b) {
      const WorldShape& sb = shapes[b];
      if (!sb.compliant || sb.side != sa.side || sb.finger < 0 || sb.finger == kThumb) continue;
      const double ka = sa.stiffness_n_per_mm3 * contact_area_mm2,
                   kb = sb.stiffness_n_per_mm3 * contact_area_mm2;
      pairs_[sa.side].push_back(
          {a, b, ka * kb / (ka + kb), bounding_radius(sa.geom) + bounding_radius(sb.geom)});
    }
  }
}

int ThumbContacts::measure_rt(int side, std::span<const Pose> poses,
                              std::span<HandCompliance::Contact> out, std::span<int> shape_a,
                              std::span<int> shape_b) const noexcept {
  int n = 0;
  for (const Pair& p : pairs_[side]) {
    if (n >= static_cast<int>(out.size())) break;
    const Pose &pa = poses[p.a], &pb = poses[p.b];
    if (sheet::norm(pa.t - pb.t) > p.reach_mm + kGapMm) continue;
    const WorldShape &a = shapes_[p.a], &b = shapes_[p.b];
    Vec3 ca, cb;
    closest_cores(a.geom, pa, b.geom, pb, ca, cb);
    const Vec3 d = cb - ca;
    const double len = sheet::norm(d);
    const double ra = core_grow(a.geom), rb = core_grow(b.geom);
    const double depth = ra + rb - len;
    if (depth <= -kGapMm || !(len > 1e-9)) continue;
    const Vec3 n_ab = (1.0 / len) * d;  // from a towards b: the way a presses b
    HandCompliance::Contact& c = out[n];
    c.link = a.link;
    c.point = ca + ra * n_ab;
    c.normal = n_ab;
    c.depth_mm = depth;
    c.stiffness_n_per_mm = p.stiffness_n_per_mm;
    c.link2 = b.link;
    c.point2 = cb - rb * n_ab;
    c.normal2 = -1.0 * n_ab;
    shape_a[n] = p.a;
    shape_b[n] = p.b;
    ++n;
  }
  return n;
}

}  // namespace crease::world
