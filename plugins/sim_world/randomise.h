// The world's randomisation, all from one seed: the sheet's pose on the table, its stiffness
// and yield strain, and every friction coefficient, each uniform in +- its range
// (WorldParams). splitmix64 (Steele, Lea, Flood 2014) so that a seed gives the same draws on
// every compiler and standard library. Non-RT (configure time).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "plugins/robot_model/robot_params.h"
#include "plugins/sim_world/world_params.h"

namespace crease::world {

class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) noexcept : s_(seed) {}
  std::uint64_t next() noexcept {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [-1, 1).
  double symmetric() noexcept { return 2.0 * static_cast<double>(next() >> 11) * 0x1.0p-53 - 1.0; }

 private:
  std::uint64_t s_;
};

// What one seed made of the nominal parameters.
struct WorldDraws {
  double sheet_dx_mm = 0, sheet_dy_mm = 0, sheet_yaw_deg = 0;
  double stiffness_scale = 1;  // link stiffness x this (compliances / this)
  double yield_scale = 1;      // yield strain x this
  double paper_table = 0, paper_paper = 0;
  std::map<std::string, double> material_friction;  // against paper
};

// Draws in a fixed order (pose, stiffness, yield, friction in the materials' name order), so
// one seed always gives the same world. randomise = false: the nominal values.
[[nodiscard]] WorldDraws draw_world(const WorldParams& p, const robot::RobotParams& robot);

// One line for the log: the seed and every draw.
[[nodiscard]] std::string describe(std::uint64_t seed, const WorldDraws& d);

}  // namespace crease::world
