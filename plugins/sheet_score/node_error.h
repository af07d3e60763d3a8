// The tracking error of a sheet against the truth: the mean distance between corresponding
// nodes (mm). RT-safe (no allocation), O(nodes).
#pragma once

#include <cmath>
#include <cstddef>

#include "core/port_types/sheet_state.h"

namespace crease::sheet_score {

// Mean node distance (mm) of `model` from `truth`; negative when they cannot be compared (a
// different grid, or no sheet: the safe value).
[[nodiscard]] inline double mean_node_distance_mm(const SheetState& model, const SheetState& truth) noexcept {
  const std::size_t n = static_cast<std::size_t>(model.nodes_u) * model.nodes_v;
  if (n == 0 || n > SheetState::kMaxNodes || model.nodes_u != truth.nodes_u || model.nodes_v != truth.nodes_v) return -1.0;
  double sum = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double dx = double(model.position_mm[k][0]) - truth.position_mm[k][0];
    const double dy = double(model.position_mm[k][1]) - truth.position_mm[k][1];
    const double dz = double(model.position_mm[k][2]) - truth.position_mm[k][2];
    sum += std::sqrt(dx * dx + dy * dy + dz * dz);
  }
  return sum / double(n);
}

}  // namespace crease::sheet_score
