// The robot's parameter file: the shipped values, and errors that name file, line, column, key.
#include "plugins/robot_model/robot_params.h"

#include <doctest/doctest.h>

#include <string>

#include "core/errors.h"
#include "robot_files.h"

using namespace crease::robot;

namespace {

const std::string& shipped_yaml() {
  static const std::string text = robot_files::read(robot_files::shipped("crease_robot.yaml"));
  return text;
}

// The shipped YAML with FROM replaced by TO, written beside a copy of the URDF; its error.
std::string error_of(const std::string& name, const std::string& from, const std::string& to) {
  robot_files::write("crease_robot.urdf", robot_files::read(robot_files::shipped("crease_robot.urdf")));
  const std::string path = robot_files::write(name, robot_files::replace(shipped_yaml(), from, to));
  try {
    (void)load_robot_params(path);
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  FAIL("no ConfigError for " << name);
  return {};
}

std::string at(const std::string& name, const std::string& edited_text, const std::string& needle, int column) {
  return robot_files::tmp_dir() + "/" + name + ":" + std::to_string(robot_files::line_of(edited_text, needle)) +
         ":" + std::to_string(column) + ": ";
}

}  // namespace

TEST_CASE("the shipped parameters: mounting, materials, friction and sensors per side") {
  const RobotParams p = load_robot_params(robot_files::shipped("crease_robot.yaml"));
  CHECK(p.urdf_path == robot_files::shipped("crease_robot.urdf"));
  const SideParams& r = p.side(Side::right);
  const SideParams& l = p.side(Side::left);
  CHECK(r.prefix == "r_");
  CHECK(l.prefix == "l_");
  CHECK(r.mount.xyz_mm == std::array<double, 3>{300, -300, 1000});
  CHECK(l.mount.xyz_mm == std::array<double, 3>{-300, -300, 1000});
  CHECK(r.mount.rpy_deg == std::array<double, 3>{180, 0, 0});
  CHECK(r.cover == "rubber");
  CHECK(l.cover == "fabric");
  CHECK(r.cover_friction == p.materials.at("rubber"));
  CHECK(l.cover_friction == p.materials.at("fabric"));
  CHECK(r.shell_friction == p.materials.at("plastic"));
  CHECK(r.cover_friction > l.cover_friction);  // seed 000 V: rubber high, fabric low
  CHECK(p.paper_table_friction == 0.35);
  CHECK(p.paper_paper_friction == 0.4);
  CHECK(r.tactile.kind == TactileKind::taxel_matrix);
  CHECK(r.tactile.taxel.pitch_mm == 3.0);
  CHECK(r.tactile.taxel.threshold_kpa > r.tactile.taxel.noise_kpa);
  CHECK(r.tactile.taxel.taxel_area_mm2 == 11.0);
  CHECK(r.tactile.taxel.contact_sigma_mm == 2.0);
  CHECK(l.tactile.kind == TactileKind::pst);
  CHECK(l.tactile.pst.rate_hz == 1000.0);
  CHECK(l.tactile.pst.noise_kpa < r.tactile.taxel.noise_kpa);  // the PST sensors are the sensitive ones
  CHECK(l.tactile.pst.highpass_time_constant_s == 30.0);
}

TEST_CASE("errors name the file, line, column and key") {
  SUBCASE("an unknown key") {
    const std::string edited = robot_files::replace(shipped_yaml(), "adc_bits: 12", "adcbits: 12");
    CHECK(error_of("k.yaml", "adc_bits: 12", "adcbits: 12") ==
          at("k.yaml", edited, "adcbits", 7) +
              "sides.right.tactile.adcbits: unknown key 'adcbits' (did you mean 'adc_bits'?)");
  }
  SUBCASE("an undefined material") {
    const std::string edited = robot_files::replace(shipped_yaml(), "cover: fabric", "cover: fabrik");
    CHECK(error_of("m.yaml", "cover: fabric", "cover: fabrik") ==
          at("m.yaml", edited, "fabrik", 12) +
              "sides.left.cover: unknown material 'fabrik' (did you mean 'fabric'?)");
  }
  SUBCASE("a bad number") {
    const std::string edited = robot_files::replace(shipped_yaml(), "paper_table: 0.35", "paper_table: lots");
    CHECK(error_of("n.yaml", "paper_table: 0.35", "paper_table: lots") ==
          at("n.yaml", edited, "lots", 16) + "world.paper_table: expected a finite number, got 'lots'");
  }
  SUBCASE("a number out of range") {
    CHECK(error_of("r.yaml", "rubber: 1.2", "rubber: -1").find("materials.rubber: must be in [0, 10], got -1") !=
          std::string::npos);
  }
  SUBCASE("a taxel calibration out of range") {
    CHECK(error_of("c.yaml", "taxel_area_mm2: 11.0", "taxel_area_mm2: 0")
              .find("sides.right.tactile.taxel_area_mm2: must be in (0, 100], got 0") != std::string::npos);
    CHECK(error_of("c2.yaml", "contact_sigma_mm: 2.0", "contact_sigma_mm: -1")
              .find("sides.right.tactile.contact_sigma_mm: must be in (0, 20], got -1") != std::string::npos);
  }
  SUBCASE("a missing mounting") {
    CHECK(error_of("mm.yaml", "    mount: {xyz_mm: [-300, -300, 1000], rpy_deg: [180, 0, 0]}\n", "")
              .find("sides.left.mount: required key is missing") != std::string::npos);
  }
  SUBCASE("an unknown tactile kind") {
    CHECK(error_of("t.yaml", "kind: pst", "kind: piezo").find("sides.left.tactile.kind: unknown tactile kind 'piezo'") !=
          std::string::npos);
  }
  SUBCASE("the same prefix twice, or one starting the other") {
    CHECK(error_of("p.yaml", "prefix: l_", "prefix: r_").find("sides.left.prefix: the sides' prefixes") !=
          std::string::npos);
    CHECK(error_of("p2.yaml", "prefix: l_", "prefix: r").find("('r_', 'r')") != std::string::npos);
  }
  SUBCASE("a URDF that is not there") {
    const std::string edited = robot_files::replace(shipped_yaml(), "urdf: crease_robot.urdf", "urdf: nothere.urdf");
    CHECK(error_of("u.yaml", "urdf: crease_robot.urdf", "urdf: nothere.urdf")
              .find(at("u.yaml", edited, "nothere", 7) + "urdf: cannot open '") == 0);
  }
  SUBCASE("bad YAML") {
    CHECK(error_of("y.yaml", "materials:\n", "materials: [\n").find(robot_files::tmp_dir() + "/y.yaml:") == 0);
  }
}
