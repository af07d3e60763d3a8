#include "plugins/arm_motion/sheet_frame.h"

#include <algorithm>
#include <cmath>

namespace crease::arm_motion {

bool sheet_frame_m(const SheetState& s, KDL::Frame& out) noexcept {
  const unsigned w = s.nodes_u, h = s.nodes_v;
  if (w < 2 || h < 2 || w * h > SheetState::kMaxNodes) return false;
  const auto node = [&](unsigned i) {
    return KDL::Vector(s.position_mm[i][0], s.position_mm[i][1], s.position_mm[i][2]) / 1000.0;
  };
  const unsigned quarter =
      std::max(1u, (h - 1) / 4);  // node (0, quarter): a quarter along the v edge
  const KDL::Vector o = node(0), u = node(w - 1), v = node(quarter * w);
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(o(i)) || !std::isfinite(u(i)) || !std::isfinite(v(i))) return false;
  KDL::Vector x = u - o;
  if (x.Norm() < 1e-6) return false;
  x.Normalize();
  KDL::Vector z = x * (v - o);
  if (z.Norm() < 1e-9) return false;
  z.Normalize();
  const KDL::Vector y = z * x;
  out = KDL::Frame(KDL::Rotation(x, y, z), o);
  return true;
}

}  // namespace crease::arm_motion
