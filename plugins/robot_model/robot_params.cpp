#include "plugins/robot_model/robot_params.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "core/config/yaml_reader.h"
#include "core/errors.h"

namespace crease::robot {
namespace {

using config::MapReader;
using config::read_int;
using config::read_number;
using config::read_string;

[[noreturn]] void fail_at(const std::string& file, const YAML::Node& node, const std::string& path,
                          const std::string& reason) {
  throw config::error_at(file, node, path, reason);
}

std::array<double, 3> read_vec3(const std::string& file, const YAML::Node& node,
                                const std::string& path, double limit) {
  if (!node.IsSequence() || node.size() != 3) fail_at(file, node, path, "expected a list of 3 numbers");
  std::array<double, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) {
    v[i] = read_number(file, node[i], path + "[" + std::to_string(i) + "]", -limit, limit, false);
  }
  return v;
}

MountPose read_mount(const std::string& file, const MapReader& side) {
  const MapReader m(file, side.require("mount"), side.path_of("mount"), {"xyz_mm", "rpy_deg"});
  MountPose p;
  p.xyz_mm = read_vec3(file, m.require("xyz_mm"), m.path_of("xyz_mm"), 10'000.0);
  p.rpy_deg = read_vec3(file, m.require("rpy_deg"), m.path_of("rpy_deg"), 360.0);
  return p;
}

double number(const std::string& file, const MapReader& m, const char* key, double lo, double hi,
              bool lo_open) {
  return read_number(file, m.require(key), m.path_of(key), lo, hi, lo_open);
}

TactileParams read_tactile(const std::string& file, const MapReader& side) {
  const YAML::Node node = side.require("tactile");
  const std::string path = side.path_of("tactile");
  if (!node.IsMap()) fail_at(file, node, path, "expected a map");
  const YAML::Node kind_node = node["kind"];
  if (!kind_node) fail_at(file, node, path + ".kind", "required key is missing");
  const std::string kind = read_string(file, kind_node, path + ".kind");
  TactileParams t;
  if (kind == "taxel_matrix") {
    const MapReader m(file, node, path,
                      {"kind", "pitch_mm", "rate_hz", "range_kpa", "adc_bits", "noise_kpa",
                       "threshold_kpa", "taxel_area_mm2", "contact_sigma_mm"});
    t.kind = TactileKind::taxel_matrix;
    auto& x = t.taxel;
    x.pitch_mm = number(file, m, "pitch_mm", 0.0, 50.0, true);
    x.rate_hz = number(file, m, "rate_hz", 0.0, 10'000.0, true);
    x.range_kpa = number(file, m, "range_kpa", 0.0, 655.35, true);  // u16 of 0.01 kPa (§6)
    x.adc_bits = static_cast<int>(read_int(file, m.require("adc_bits"), m.path_of("adc_bits"), 1, 16));
    x.noise_kpa = number(file, m, "noise_kpa", 0.0, x.range_kpa, false);
    x.threshold_kpa = number(file, m, "threshold_kpa", 0.0, x.range_kpa, false);
    x.taxel_area_mm2 = number(file, m, "taxel_area_mm2", 0.0, 100.0, true);
    x.contact_sigma_mm = number(file, m, "contact_sigma_mm", 0.0, 20.0, true);
  } else if (kind == "pst") {
    const MapReader m(file, node, path,
                      {"kind", "rate_hz", "range_kpa", "kpa_per_n", "noise_kpa", "drift_kpa_per_s",
                       "highpass_time_constant_s"});
    t.kind = TactileKind::pst;
    auto& x = t.pst;
    x.rate_hz = number(file, m, "rate_hz", 0.0, 10'000.0, true);
    x.range_kpa = number(file, m, "range_kpa", 0.0, 655.35, true);  // u16 of 0.01 kPa (§3)
    x.kpa_per_n = number(file, m, "kpa_per_n", 0.0, 1000.0, true);
    x.noise_kpa = number(file, m, "noise_kpa", 0.0, x.range_kpa, false);
    x.drift_kpa_per_s = number(file, m, "drift_kpa_per_s", -x.range_kpa, x.range_kpa, false);
    x.highpass_time_constant_s = number(file, m, "highpass_time_constant_s", 0.0, 1e6, true);
  } else {
    std::string reason = "unknown tactile kind '" + kind + "' (taxel_matrix or pst)";
    fail_at(file, kind_node, path + ".kind", reason);
  }
  return t;
}

bool valid_name(const std::string& p) {
  for (char c : p) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return !p.empty();
}

double material_friction(const std::string& file, const MapReader& side, const char* key,
                         const std::map<std::string, double>& materials, std::string& name) {
  const YAML::Node n = side.require(key);
  name = read_string(file, n, side.path_of(key));
  const auto it = materials.find(name);
  if (it == materials.end()) {
    std::vector<std::string> names;
    for (const auto& kv : materials) names.push_back(kv.first);
    std::string reason = "unknown material '" + name + "'";
    const std::string guess = config::did_you_mean(name, names);
    if (!guess.empty()) reason += " (did you mean '" + guess + "'?)";
    fail_at(file, n, side.path_of(key), reason);
  }
  return it->second;
}

// `materials`: any names (a-z, 0-9, '_'), each a Coulomb coefficient in [0, 10].
std::map<std::string, double> read_materials(const std::string& file, const YAML::Node& node) {
  if (!node.IsMap() || node.size() == 0) fail_at(file, node, "materials", "expected a map of name: coefficient");
  std::map<std::string, double> out;
  for (auto it = node.begin(); it != node.end(); ++it) {
    const YAML::Node key = it->first;
    if (!key.IsScalar() || !valid_name(key.Scalar())) {
      fail_at(file, key, "materials", "material names are lower-case letters, digits and '_'");
    }
    const std::string path = "materials." + key.Scalar();
    if (out.count(key.Scalar())) fail_at(file, key, path, "duplicate key '" + key.Scalar() + "'");
    out[key.Scalar()] = read_number(file, it->second, path, 0.0, 10.0, false);
  }
  return out;
}

RobotParams parse(const std::string& file, const YAML::Node& root) {
  const MapReader top(file, root, "", {"urdf", "sides", "materials", "world"});
  RobotParams p;
  p.file = file;

  const YAML::Node urdf = top.require("urdf");
  const std::filesystem::path rel = read_string(file, urdf, "urdf");
  p.urdf_path = rel.is_absolute() ? rel.string()
                                  : (std::filesystem::path(file).parent_path() / rel).string();
  if (!std::ifstream(p.urdf_path)) fail_at(file, urdf, "urdf", "cannot open '" + p.urdf_path + "'");

  p.materials = read_materials(file, top.require("materials"));

  const MapReader world(file, top.require("world"), "world", {"paper_table", "paper_paper"});
  p.paper_table_friction = number(file, world, "paper_table", 0.0, 10.0, false);
  p.paper_paper_friction = number(file, world, "paper_paper", 0.0, 10.0, false);

  const MapReader sides(file, top.require("sides"), "sides", {"right", "left"});
  for (int s = 0; s < kSides; ++s) {
    const std::string key(kSideNames[s]);
    const MapReader side(file, sides.require(key), sides.path_of(key),
                         {"prefix", "mount", "cover", "shell", "tactile"});
    SideParams& sp = p.sides[s];
    const YAML::Node prefix = side.require("prefix");
    sp.prefix = read_string(file, prefix, side.path_of("prefix"));
    if (!valid_name(sp.prefix)) {
      fail_at(file, prefix, side.path_of("prefix"), "must be lower-case letters, digits and '_'");
    }
    const std::string& other = p.sides[0].prefix;
    if (s > 0 && (sp.prefix.rfind(other, 0) == 0 || other.rfind(sp.prefix, 0) == 0)) {
      fail_at(file, prefix, side.path_of("prefix"),
              "the sides' prefixes must not start one another ('" + other + "', '" + sp.prefix + "')");
    }
    sp.mount = read_mount(file, side);
    sp.cover_friction = material_friction(file, side, "cover", p.materials, sp.cover);
    sp.shell_friction = material_friction(file, side, "shell", p.materials, sp.shell);
    sp.tactile = read_tactile(file, side);
  }
  return p;
}

}  // namespace

RobotParams load_robot_params(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw ConfigError(path + ": cannot open the robot's parameter file");
  } catch (const YAML::ParserException& e) {
    throw ConfigError(path + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  // The strict readers of core/config throw config::ConfigError; the robot model's callers
  // catch crease::ConfigError, with the same "FILE:LINE:COLUMN: KEY.PATH: reason" text.
  try {
    return parse(path, root);
  } catch (const config::ConfigError& e) {
    throw ConfigError(e.what());
  }
}

}  // namespace crease::robot
