#include "plugins/sim_world/randomise.h"

#include <cstdio>

namespace crease::world {

WorldDraws draw_world(const WorldParams& p, const robot::RobotParams& robot) {
  WorldDraws d;
  d.paper_table = robot.paper_table_friction;
  d.paper_paper = robot.paper_paper_friction;
  d.material_friction = robot.materials;
  if (!p.randomise) return d;
  SplitMix64 rng(p.seed);
  d.sheet_dx_mm = p.sheet_offset_mm * rng.symmetric();
  d.sheet_dy_mm = p.sheet_offset_mm * rng.symmetric();
  d.sheet_yaw_deg = p.sheet_yaw_deg * rng.symmetric();
  d.stiffness_scale = 1.0 + p.stiffness_fraction * rng.symmetric();
  d.yield_scale = 1.0 + p.yield_fraction * rng.symmetric();
  d.paper_table *= 1.0 + p.friction_fraction * rng.symmetric();
  d.paper_paper *= 1.0 + p.friction_fraction * rng.symmetric();
  for (auto& [name, mu] : d.material_friction) mu *= 1.0 + p.friction_fraction * rng.symmetric();
  return d;
}

std::string describe(std::uint64_t seed, const WorldDraws& d) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "seed %llu: sheet offset (%.2f, %.2f) mm, yaw %.2f deg, stiffness x%.3f, yield x%.3f, "
                "friction paper-table %.3f, paper-paper %.3f",
                static_cast<unsigned long long>(seed), d.sheet_dx_mm, d.sheet_dy_mm, d.sheet_yaw_deg,
                d.stiffness_scale, d.yield_scale, d.paper_table, d.paper_paper);
  std::string out = buf;
  for (const auto& [name, mu] : d.material_friction) {
    std::snprintf(buf, sizeof buf, ", %s %.3f", name.c_str(), mu);
    out += buf;
  }
  return out;
}

}  // namespace crease::world
