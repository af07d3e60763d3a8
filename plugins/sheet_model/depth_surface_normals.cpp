#include "depth_surface_normals.h"

#include <algorithm>

namespace crease::sheet {

void estimate_surface_normals_rt(int w, int h, std::span<NormalTarget> targets,
                                 std::span<const std::int32_t> target_node,
                                 std::span<std::int32_t> node_target) noexcept {
  const int n = static_cast<int>(std::min(targets.size(), target_node.size()));
  std::fill(node_target.begin(), node_target.end(), -1);
  const auto cells = static_cast<std::int64_t>(node_target.size());
  for (int k = 0; k < n; ++k)
    if (target_node[k] >= 0 && target_node[k] < cells) node_target[target_node[k]] = k;
  const auto at = [&](int i, int j) -> int {
    return i < 0 || j < 0 || i >= w || j >= h || std::int64_t{j} * w + i >= cells
               ? -1
               : node_target[j * w + i];
  };
  const auto diff = [&](int a, int c,
                        int b) -> Vec3 {  // targets a, c, b in a row: b - a, b - c or c - a
    if (a >= 0 && b >= 0) return targets[b].world_mm - targets[a].world_mm;
    if (c >= 0 && b >= 0) return targets[b].world_mm - targets[c].world_mm;
    if (a >= 0 && c >= 0) return targets[c].world_mm - targets[a].world_mm;
    return Vec3{};
  };
  for (int k = 0; k < n; ++k) {
    targets[k].surface_normal = Vec3{};
    const std::int32_t node = target_node[k];
    if (node < 0 || node >= cells || w <= 0) continue;
    const int i = node % w, j = node / w;
    const Vec3 du = diff(at(i - 1, j), k, at(i + 1, j)), dv = diff(at(i, j - 1), k, at(i, j + 1));
    const Vec3 nrm = cross(du, dv);
    // |du x dv| = |du||dv| sin: over 0.5 is more than 30 deg from parallel.
    if (norm(du) > 1e-6 && norm(dv) > 1e-6 && norm(nrm) > 0.5 * norm(du) * norm(dv))
      targets[k].surface_normal = normalized(nrm);
  }
}

}  // namespace crease::sheet
