// A model's shape as the `sheet_state` payload (core/port_types/sheet_state.h): grid, node
// positions and normals, per-link strain (the first SheetState::kMaxLinks links), creases.
// The quality fields (fit error, observations, rollbacks) are the caller's: the tracking
// model (SheetRunner) and the simulated world (plugins/sim_world) fill them each their way.
#pragma once

#include <cstdint>
#include <span>

#include "core/port_types/sheet_state.h"
#include "sheet_model.h"

namespace crease::sheet {

// normals, strain: scratch of node_count() and link_count() entries. RT.
void write_sheet_state(const SheetModel& m, std::span<Vec3> normals, std::span<double> strain, std::int64_t now_ns,
                       std::uint64_t step, SheetState& out) noexcept;

}  // namespace crease::sheet
