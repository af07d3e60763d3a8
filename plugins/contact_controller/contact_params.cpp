#include "plugins/contact_controller/contact_params.h"

#include <string>
#include <vector>

#include "core/config/yaml_reader.h"
#include "plugins/robot_model/robot_layout.h"

namespace crease::contact {

std::array<double, kJoints> read_joint_map(const Params& p, const char* key, double lo, double hi,
                                           const std::array<double, kJoints>& fallback) {
  if (!p.has(key)) return fallback;
  const YAML::Node node = p.raw(key);
  const Params map = p.child(key);
  std::array<double, kJoints> out{};
  std::vector<std::string> names(robot::kHandJointNames.begin(), robot::kHandJointNames.end());
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string name = it->first.as<std::string>();
    const int j = robot::hand_joint_index(name);
    if (j < 0) {
      std::string why = "unknown joint '" + name + "'";
      const std::string guess = config::did_you_mean(name, names);
      why += guess.empty() ? " (the hand's joints: drivers/README.md §3)" : " (did you mean '" + guess + "'?)";
      map.fail(name, why);
    }
    out[static_cast<std::size_t>(j)] = map.get_in_range<double>(name, 0.0, lo, hi);
  }
  return out;
}

ContactConfig read_contact_config(const Params& p) {
  ContactConfig c;
  std::array<double, kJoints> selection{};
  for (int j = 0; j < kJoints; ++j)
    if (robot::is_finger_flexion_joint(j) || robot::kHandJointNames[static_cast<std::size_t>(j)] == "WRJ1")
      selection[static_cast<std::size_t>(j)] = 1.0;
  c.weight = read_joint_map(p, "weights", 0.0, 100.0, selection);
  bool any = false;
  for (double w : c.weight) any = any || w > 0;
  if (!any) p.fail("weights", "selects no joint: every weight is 0");
  c.enter_rad = p.get_in_range<double>("enter_rad", c.enter_rad, 1e-5, 1.0);
  c.exit_rad = p.get_in_range<double>("exit_rad", c.exit_rad, 0.0, 1.0);
  if (!(c.exit_rad < c.enter_rad)) p.fail("exit_rad", "must be below enter_rad (the release's hysteresis)");
  c.noise_factor = p.get_in_range<double>("noise_factor", c.noise_factor, 0.0, 100.0);
  c.spike_margin = p.get_in_range<double>("spike_margin", c.spike_margin, 0.0, 100.0);
  c.debounce_cycles = p.get_in_range<int>("debounce_cycles", c.debounce_cycles, 1, 1000);
  c.settle_cycles = p.get_in_range<int>("settle_cycles", c.settle_cycles, 1, 100'000);
  c.settle_band_rad = p.get_in_range<double>("settle_band_rad", c.settle_band_rad, 0.0, 0.1);
  c.rearm_rad = p.get_in_range<double>("rearm_rad", c.rearm_rad, 0.0, 3.0);
  const std::string tactile = p.get<std::string>("tactile", "none");
  if (tactile == "none") c.tactile = TactileSource::none;
  else if (tactile == "pst") c.tactile = TactileSource::pst;
  else if (tactile == "taxels") c.tactile = TactileSource::taxels;
  else p.fail("tactile", "expected none, pst (hand_state's pressures) or taxels (the tactile port), got '" + tactile + "'");
  c.tactile_enter_kpa = p.get_in_range<double>("tactile_enter_kpa", c.tactile_enter_kpa, 1e-6, 1e4);
  c.tactile_exit_kpa = p.get_in_range<double>("tactile_exit_kpa", c.tactile_exit_kpa, 0.0, 1e4);
  if (!(c.tactile_exit_kpa < c.tactile_enter_kpa))
    p.fail("tactile_exit_kpa", "must be below tactile_enter_kpa (the release's hysteresis)");
  c.baseline_time_constant_s = p.get_in_range<double>("baseline_time_constant_s", c.baseline_time_constant_s, 1e-3, 1e4);
  c.stale_cycles = p.get_in_range<int>("stale_cycles", c.stale_cycles, 0, 1000);
  c.max_tactile_age_ns = static_cast<std::int64_t>(
      1e6 * p.get_in_range<double>("max_tactile_age_ms", static_cast<double>(c.max_tactile_age_ns) / 1e6, 0.0, 1000.0));
  return c;
}

}  // namespace crease::contact
