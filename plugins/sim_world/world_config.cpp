#include "plugins/sim_world/world_config.h"

#include <cmath>
#include <numbers>

#include "drivers/host/bus_prefix.h"

namespace crease::world {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

// A list of N numbers in degrees under KEY (absent: FALLBACK), as radians.
template <std::size_t N>
std::array<double, N> read_angles_deg(const Params& p, const char* key, const double (&fallback)[N]) {
  std::array<double, N> out{};
  if (!p.has(key)) {
    for (std::size_t i = 0; i < N; ++i) out[i] = fallback[i] * kRad;
    return out;
  }
  const YAML::Node n = p.raw(key);
  if (!n.IsSequence() || n.size() != N) p.fail(key, "expected a list of " + std::to_string(N) + " angles in degrees");
  for (std::size_t i = 0; i < N; ++i) {
    double v = 0;
    try {
      v = n[i].as<double>();
    } catch (const YAML::Exception&) {
      p.fail(key, "element " + std::to_string(i) + " is not a number");
    }
    if (!std::isfinite(v) || std::fabs(v) > 360.0) p.fail(key, "element " + std::to_string(i) + " must be in [-360, 360] deg");
    out[i] = v * kRad;
  }
  return out;
}

// The table top's extent: [x_min, x_max, y_min, y_max] mm, each a number or null (no edge on
// that side); absent: a plane.
void read_table_extent(const Params& p, std::array<double, 4>& out) {
  const char* key = "table_extent_mm";
  if (!p.has(key)) return;
  const YAML::Node n = p.raw(key);
  if (!n.IsSequence() || n.size() != 4) p.fail(key, "expected [x_min, x_max, y_min, y_max] mm (null: no edge)");
  for (std::size_t i = 0; i < 4; ++i) {
    if (n[i].IsNull()) continue;  // the default: no edge
    double v = 0;
    try {
      v = n[i].as<double>();
    } catch (const YAML::Exception&) {
      p.fail(key, "element " + std::to_string(i) + " is not a number or null");
    }
    if (!std::isfinite(v) || std::fabs(v) > 5000.0) p.fail(key, "element " + std::to_string(i) + " must be in [-5000, 5000] mm");
    out[i] = v;
  }
  if (!(out[0] < out[1]) || !(out[2] < out[3])) p.fail(key, "each minimum must be below its maximum");
}

}  // namespace

WorldPluginConfig read_world_config(const Params& p) {
  WorldPluginConfig c;
  c.robot_yaml = p.get_path("robot");
  WorldParams& w = c.world;
  w.seed = static_cast<std::uint64_t>(p.get_in_range<long long>("seed", 1, 0, (1LL << 62)));
  w.randomise = p.get<bool>("randomise", true);
  w.sheet_offset_mm = p.get_in_range<double>("sheet_offset_mm", w.sheet_offset_mm, 0.0, 100.0);
  w.sheet_yaw_deg = p.get_in_range<double>("sheet_yaw_deg", w.sheet_yaw_deg, 0.0, 90.0);
  w.stiffness_fraction = p.get_in_range<double>("stiffness_fraction", w.stiffness_fraction, 0.0, 0.5);
  w.yield_fraction = p.get_in_range<double>("yield_fraction", w.yield_fraction, 0.0, 0.5);
  w.friction_fraction = p.get_in_range<double>("friction_fraction", w.friction_fraction, 0.0, 0.5);
  sheet::GridParams& g = w.sheet.grid;
  g.nodes_u = p.get_in_range<int>("nodes_u", g.nodes_u, 3, 64);
  g.nodes_v = p.get_in_range<int>("nodes_v", g.nodes_v, 3, 64);
  g.origin_mm.x = p.get_in_range<double>("origin_x_mm", g.origin_mm.x, -1000.0, 1000.0);
  g.origin_mm.y = p.get_in_range<double>("origin_y_mm", g.origin_mm.y, -1000.0, 1000.0);
  g.turn_deg = p.get_in_range<double>("sheet_turn_deg", g.turn_deg, -180.0, 180.0);
  w.sheet.solver.substeps = p.get_in_range<int>("substeps", w.sheet.solver.substeps, 1, 16);
  w.sheet.solver.max_strain =
      p.get_in_range<double>("max_strain", w.sheet.solver.max_strain, 0.0, 0.2);
  w.table_height_mm = p.get_in_range<double>("table_height_mm", w.table_height_mm, -500.0, 500.0);
  read_table_extent(p, w.table_extent_mm);
  w.table_edge_radius_mm =
      p.get_in_range<double>("table_edge_radius_mm", w.table_edge_radius_mm, 0.0, 20.0);
  w.initial_stiffness_nm_per_rad =
      p.get_in_range<double>("initial_stiffness_nm_per_rad", w.initial_stiffness_nm_per_rad, 0.0, 1000.0);
  const double zero_hand[robot::kHandJoints] = {};
  w.initial_arm_rad[0] = read_angles_deg(p, "arm_r_deg", kParkedArmDeg[0]);
  w.initial_arm_rad[1] = read_angles_deg(p, "arm_l_deg", kParkedArmDeg[1]);
  w.initial_hand_rad[0] = read_angles_deg(p, "hand_r_deg", zero_hand);
  w.initial_hand_rad[1] = read_angles_deg(p, "hand_l_deg", zero_hand);
  // The physics switches (world_params.h), for the failing variants of tests.
  w.hand_contacts = p.get<bool>("hand_contacts", true);
  w.thumb_contacts = p.get<bool>("thumb_contacts", true);
  w.finger_friction = p.get<bool>("finger_friction", true);
  w.table_friction = p.get<bool>("table_friction", true);
  w.joint_compliance = p.get<bool>("joint_compliance", true);

  c.truth_every_steps = p.get_in_range<int>("truth_every_steps", c.truth_every_steps, 1, 1000);
  c.truth_stride = p.get_in_range<int>("truth_stride", c.truth_stride, 1, 8);
  c.shapes_every_steps = p.get_in_range<int>("shapes_every_steps", c.truth_every_steps, 1, 1000);
  if ((g.nodes_u - 1) % c.truth_stride != 0 || (g.nodes_v - 1) % c.truth_stride != 0) {
    p.fail("truth_stride", "must divide the grid's intervals (nodes_u - 1 = " + std::to_string(g.nodes_u - 1) +
                               ", nodes_v - 1 = " + std::to_string(g.nodes_v - 1) + ")");
  }
  c.bus_prefix = *drivers::bus_prefix_from_params(p, std::string(drivers::kAutoBusPrefix));
  c.bitrate = static_cast<std::uint32_t>(p.get_in_range<int>("bitrate", 1'000'000, 10'000, 1'000'000));
  c.data_bitrate = static_cast<std::uint32_t>(p.get_in_range<int>("data_bitrate", 5'000'000, 10'000, 8'000'000));
  c.device_watchdog_ms = p.get_in_range<double>("device_watchdog_ms", 20.0, 1.0, 1000.0);
  c.tactile_link = p.get<std::string>("tactile_link", c.tactile_link);
  if (c.tactile_link == "none") {
    c.tactile_link.clear();
  } else if (!drivers::valid_link_name(c.tactile_link)) {
    p.fail("tactile_link", "must be 1..32 of [A-Za-z0-9._-], or none");
  }
  c.faults = p.get<bool>("faults", false);
  BusFaultConfig& f = c.bus_faults;
  f.seed = static_cast<std::uint64_t>(p.get_in_range<long long>("fault_seed", static_cast<long long>(w.seed), 0, (1LL << 62)));
  f.drop = p.get_in_range<double>("fault_drop", f.drop, 0.0, 0.5);
  f.corrupt = p.get_in_range<double>("fault_corrupt", f.corrupt, 0.0, 0.5);
  f.delay_ms = p.get_in_range<double>("fault_delay_ms", f.delay_ms, 0.0, 1000.0);
  f.delay_burst_s = p.get_in_range<double>("fault_delay_burst_s", f.delay_burst_s, 0.0, 60.0);
  f.bus_off = p.get<bool>("fault_bus_off", f.bus_off);
  f.host_node = static_cast<std::uint32_t>(p.get_in_range<int>("fault_host_node", static_cast<int>(f.host_node), 0, 100000));
  f.from_s = p.get_in_range<double>("fault_from_s", f.from_s, 0.0, 1e6);
  f.to_s = p.get_in_range<double>("fault_to_s", f.to_s, f.from_s, 1e6);
  return c;
}

}  // namespace crease::world
