// The per-node passes of an XPBD substep (seed 001 Eq. 1 and the velocity update), over the
// node-major xyz doubles of positions, velocities and previous positions: AVX2+FMA four
// doubles at a time when the CPU has it (runtime check), else node by node.
// keep: per component (3 per node), all bits set for a free node and 0 for a pinned one.
// RT: no allocation.
#pragma once

#include <cstdint>
#include <span>

#include "vec3.h"

namespace crease::sheet {

// prev := x; free nodes: v := damp (v + dt_s g), x += dt_s v; pinned: x := pin, v kept.
void predict_rt(std::span<Vec3> x, std::span<Vec3> v, std::span<Vec3> prev, std::span<const Vec3> pin,
                std::span<const std::int64_t> keep, Vec3 gravity_mm_per_s2, double damp, double dt_s,
                bool simd) noexcept;

// Free nodes: v := (x - prev) / dt_s; above vcap the move of the substep is shortened to
// vcap dt_s (x := prev + dt_s v). Pinned nodes: v := 0.
void update_velocities_rt(std::span<Vec3> x, std::span<Vec3> v, std::span<const Vec3> prev,
                          std::span<const std::int64_t> keep, double dt_s, double vcap_mm_per_s,
                          bool simd) noexcept;

// True when this CPU runs the AVX2+FMA passes.
[[nodiscard]] bool node_passes_simd_available() noexcept;

}  // namespace crease::sheet
