// The observed surface's normal at depth targets that sit on grid nodes (the depth tracker's
// do), from the targets on the node's grid neighbours: the differences along u and along v
// (central; one-sided where one neighbour has no target), their cross product normalised (the
// printed face's side for a sheet seen as laid out: u x v). None (zero) where both neighbours
// along u or along v have no target, or the two differences are within 30 deg of parallel.
// sheet_model's depth springs act along the bisector of this and the model's normal.
// RT: no allocation (the caller owns the per-node scratch).
#pragma once

#include <cstdint>
#include <span>

#include "sheet_model.h"

namespace crease::sheet {

// TARGETS[k] sits on grid node TARGET_NODE[k] (-1: on none; its normal is left zero) of a
// W x H grid; NODE_TARGET is scratch of W * H entries. Writes every target's surface_normal.
void estimate_surface_normals_rt(int w, int h, std::span<NormalTarget> targets,
                                 std::span<const std::int32_t> target_node,
                                 std::span<std::int32_t> node_target) noexcept;

}  // namespace crease::sheet
