// The robot's parameter file beside its URDF (config/robot/crease_robot.yaml): the mounting of
// each arm, the material of each surface and its friction, the tactile sensors' figures.
//
//   const RobotParams p = load_robot_params("config/robot/crease_robot.yaml");
//
// Everything is validated on load; a bad file throws crease::ConfigError
//   FILE:LINE:COLUMN: KEY.PATH: reason
// e.g. "crease_robot.yaml:13:12: sides.right.cover: unknown material 'rubbr' (did you mean
// 'rubber'?)". Unknown keys are errors. Millimetres, degrees, seconds, kPa, as the file. Non-RT.
#pragma once

#include <array>
#include <map>
#include <string>

#include "plugins/robot_model/robot_layout.h"

namespace crease::robot {

// world <- arm base. rpy as URDF: R = Rz(yaw) Ry(pitch) Rx(roll), fixed axes.
struct MountPose {
  std::array<double, 3> xyz_mm{};
  std::array<double, 3> rpy_deg{};
};

// The right hand's taxel matrices (drivers/README.md §6).
struct TaxelMatrixParams {
  double pitch_mm = 3.0;
  double rate_hz = 250.0;
  double range_kpa = 250.0;
  int adc_bits = 12;
  double noise_kpa = 1.0;      // standard deviation of the noise floor
  double threshold_kpa = 8.0;  // pressures below read 0
  // Calibration: the pad area each taxel stands for (mm^2): a fingertip's normal force is the
  // sum of its taxels' pressures times this (kPa x mm^2 / 1000 = N). The simulated sensor
  // (plugins/sim_world/tactile_model.h) spreads a contact's force as a Gaussian of standard
  // deviation contact_sigma_mm over the pad.
  double taxel_area_mm2 = 9.0;
  double contact_sigma_mm = 2.0;
};

// The left hand's PST air-pressure sensors (drivers/README.md §3, pressure frame).
struct PstParams {
  double rate_hz = 1000.0;
  double range_kpa = 100.0;
  double kpa_per_n = 10.0;  // calibration: cavity pressure per newton of fingertip force
  double noise_kpa = 0.01;
  double drift_kpa_per_s = 0.0;
  double highpass_time_constant_s = 30.0;  // drift compensation of the sensor electronics
};

enum class TactileKind : std::uint8_t { taxel_matrix, pst };

struct TactileParams {
  TactileKind kind = TactileKind::taxel_matrix;
  TaxelMatrixParams taxel;  // meaningful when kind == taxel_matrix
  PstParams pst;            // meaningful when kind == pst
};

struct SideParams {
  std::string prefix;         // of this side's links and joints in the URDF, e.g. "r_"
  MountPose mount;
  std::string cover;          // material of the fingertip covers (URDF surface `cover`)
  std::string shell;          // material of every other surface (URDF surface `shell`)
  double cover_friction = 0;  // Coulomb coefficients against paper, from `materials`
  double shell_friction = 0;
  TactileParams tactile;
};

struct RobotParams {
  std::string file;       // the parameter file, as given
  std::string urdf_path;  // resolved against the parameter file's folder
  std::array<SideParams, kSides> sides;         // indexed by Side
  std::map<std::string, double> materials;      // name -> Coulomb coefficient against paper
  double paper_table_friction = 0;
  double paper_paper_friction = 0;

  [[nodiscard]] const SideParams& side(Side s) const noexcept {
    return sides[static_cast<int>(s)];
  }
};

// Throws crease::ConfigError (file, line, column, key path) on any problem, including a URDF
// path that cannot be opened.
[[nodiscard]] RobotParams load_robot_params(const std::string& path);

}  // namespace crease::robot
