#include "plugins/force_controller/force_params.h"

#include <string>
#include <vector>

#include "core/config/yaml_reader.h"
#include "plugins/robot_model/robot_model.h"

namespace crease::force {
namespace {

std::array<double, kJoints> default_alpha() {
  std::array<double, kJoints> a{};
  for (int j = 0; j < kJoints; ++j) {
    if (!robot::is_finger_flexion_joint(j)) continue;
    a[static_cast<std::size_t>(j)] = robot::kHandJointNames[static_cast<std::size_t>(j)].ends_with("J3") ? 1.0 : 0.4;
  }
  return a;
}

// Each key of the map KEY, a hand joint's name, with its index; an unknown name fails naming it.
template <typename Each>
void for_each_joint(const Params& p, const std::string& key, Each each) {
  const YAML::Node node = p.raw(key);
  const Params map = p.child(key);
  const std::vector<std::string> names(robot::kHandJointNames.begin(), robot::kHandJointNames.end());
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string name = it->first.as<std::string>();
    const int j = robot::hand_joint_index(name);
    if (j < 0) {
      const std::string guess = config::did_you_mean(name, names);
      map.fail(name, "unknown joint '" + name + "'" + (guess.empty() ? "" : " (did you mean '" + guess + "'?)"));
    }
    each(map, name, j);
  }
}

std::array<double, kJoints> read_alpha(const Params& p) {
  if (!p.has("alpha")) return default_alpha();
  const Params map = p.child("alpha");
  std::array<double, kJoints> out{};
  for_each_joint(p, "alpha", [&](const Params& m, const std::string& name, int j) {
    if (!robot::is_finger_flexion_joint(j))
      m.fail(name, "not a finger's flexion joint (J3 or J2 of ff, mf, rf, lf; the thumb is excluded)");
    out[static_cast<std::size_t>(j)] = m.get_in_range<double>(name, 0.0, 0.0, 10.0);
  });
  // Seed 000: stronger flexion of the proximal joints, or the fingers curl in.
  for (int j = 0; j < kJoints; ++j) {
    const std::string_view n = robot::kHandJointNames[static_cast<std::size_t>(j)];
    if (!robot::is_finger_flexion_joint(j) || !n.ends_with("J2")) continue;
    const double distal = out[static_cast<std::size_t>(j)], proximal = out[static_cast<std::size_t>(j - 1)];
    if (distal > proximal)
      map.fail(std::string(n), "alpha of " + std::string(n) + " must not exceed its finger's J3 (" +
                                   format_number(proximal) + "): seed 000 flexes the proximal joints more");
  }
  return out;
}

// default_stiffness for every joint, joint_stiffness {NAME: N m/rad} over it.
std::array<double, kJoints> read_stiffness(const Params& p) {
  std::array<double, kJoints> out = filled(p.get_in_range<double>("default_stiffness", 2.0, 0.0, 655.35));
  if (!p.has("joint_stiffness")) return out;
  for_each_joint(p, "joint_stiffness", [&](const Params& m, const std::string& name, int j) {
    out[static_cast<std::size_t>(j)] = m.get_in_range<double>(name, 0.0, 0.0, 655.35);
  });
  return out;
}

}  // namespace

ForceConfig read_force_config(const Params& p) {
  ForceConfig c;
  const std::string side = p.get<std::string>("side");
  robot::Side s = robot::Side::right;
  if (side == "left") s = robot::Side::left;
  else if (side != "right") p.fail("side", "expected right or left, got '" + side + "'");
  const std::string robot_file = p.get_path("robot");
  const robot::RobotModel model = robot::RobotModel::load(robot_file);
  const robot::TactileParams& t = model.params().side(s).tactile;
  c.sensor = t.kind;
  c.kpa_per_n = t.pst.kpa_per_n;
  c.pst_highpass_s = p.get<bool>("undo_highpass", true) ? t.pst.highpass_time_constant_s : 0.0;
  c.taxel_area_mm2 = t.taxel.taxel_area_mm2;
  const auto& joints = model.hand_joints(s);
  for (int j = 0; j < kJoints; ++j) {
    c.lower[static_cast<std::size_t>(j)] = joints[static_cast<std::size_t>(j)].lower_rad;
    c.upper[static_cast<std::size_t>(j)] = joints[static_cast<std::size_t>(j)].upper_rad;
  }

  c.alpha = read_alpha(p);
  c.k_p = p.get_in_range<double>("k_p", c.k_p, 0.0, 100.0);
  c.max_flex_rad = p.get_in_range<double>("max_flex_rad", c.max_flex_rad, 0.0, 3.0);
  c.max_rate_rad_s = p.get_in_range<double>("max_rate_rad_s", c.max_rate_rad_s, 1e-3, 20.0);
  c.retreat_rad = p.get_in_range<double>("retreat_rad", c.retreat_rad, 0.0, 1.5);
  c.default_stiffness = read_stiffness(p);
  c.force_limit_n = p.get_in_range<double>("force_limit_n", c.force_limit_n, 0.01, 100.0);
  c.force_limit_samples =
      p.get_in_range<int>("force_limit_samples", c.force_limit_samples, 1, 1000);
  c.max_goal_force_n = p.get_in_range<double>("max_goal_force_n", 0.8 * c.force_limit_n, 0.0, 100.0);
  if (!(c.max_goal_force_n < c.force_limit_n)) p.fail("max_goal_force_n", "must be below force_limit_n");
  c.settle_band = p.get_in_range<double>("settle_band", c.settle_band, 1e-4, 1.0);
  c.settle_band_n = p.get_in_range<double>("settle_band_n", c.settle_band_n, 0.0, 10.0);
  c.settle_hold_s = p.get_in_range<double>("settle_hold_s", c.settle_hold_s, 0.0, 10.0);
  const std::string bad = p.get<std::string>("on_bad_input", "hold");
  if (bad == "hold") c.on_bad_input = OnBadInput::hold;
  else if (bad == "retreat") c.on_bad_input = OnBadInput::retreat;
  else p.fail("on_bad_input", "expected hold or retreat, got '" + bad + "'");
  c.stale_cycles = p.get_in_range<int>("stale_cycles", c.stale_cycles, 0, 1000);
  c.max_tactile_age_ns = static_cast<std::int64_t>(1e6 * p.get_in_range<double>("max_tactile_age_ms", 20.0, 0.0, 1000.0));
  c.max_contact_age_ns = static_cast<std::int64_t>(1e6 * p.get_in_range<double>("max_contact_age_ms", 5.0, 0.0, 1000.0));
  c.baseline_time_constant_s = p.get_in_range<double>("baseline_time_constant_s", c.baseline_time_constant_s, 1e-3, 1e4);
  c.anti_windup = p.get<bool>("anti_windup", true);
  const std::string start = p.get<std::string>("start", "limp");
  if (start == "limp") c.start_limp = true;
  else if (start == "hold") c.start_limp = false;
  else p.fail("start", "expected limp or hold, got '" + start + "'");
  return c;
}

}  // namespace crease::force
