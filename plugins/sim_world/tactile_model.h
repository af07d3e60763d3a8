// The hands' simulated tactile sensors (seed 000 Section V), from the world's fingertip forces
// to what the drivers publish:
//  - the right hand's taxel matrices (crease::Tactile, drivers/README.md §6): 34 taxels per
//    fingertip on a 3 mm grid over the pad; a contact's normal force spreads over the pad as a
//    Gaussian of standard deviation contact_sigma_mm about the contact point, each taxel reads
//    the pressure at its centre (kPa) with noise, below threshold_kpa it reads 0, it saturates
//    at range_kpa and is quantised to the ADC's step. The force back from a matrix:
//    sum of its pressures x taxel_area_mm2 / 1000 (N), the calibration the controllers use.
//  - the left hand's PST air-pressure sensors (HandState::pressure_kpa, §3): cavity pressure
//    kpa_per_n x force, plus a drift, through the sensor electronics' high-pass (a held force
//    reads as decaying with highpass_time_constant_s), with noise, clipped to [0, range_kpa]
//    and quantised to the wire's 0.01 kPa.
// Figures and calibration: config/robot/crease_robot.yaml (robot::TactileParams). Noise from
// one seed (splitmix64 and Box-Muller): the same seed, the same readings.
//
//   TactileModel right(robot.params().side(Side::right).tactile, seed);
//   right.taxels_rt(world.state().hand[0], tactile.pressure_kpa);      // each taxel sample
//   TactileModel left(robot.params().side(Side::left).tactile, seed);
//   left.pst_rt(world.state().hand[1], dt_s, hand_state.pressure_kpa); // each world step
#pragma once

#include <array>
#include <cstdint>

#include "core/port_types/world_state.h"
#include "plugins/robot_model/robot_params.h"
#include "plugins/sim_world/randomise.h"

namespace crease::world {

class TactileModel {
 public:
  static constexpr int kFingertips = WorldHand::kFingertips;
  static constexpr int kTaxels = 34;
  // Taxel centres in the pad frame (mm; x along the finger towards its tip, y across): a 6 x 6
  // grid at the pitch, centred on the pad frame's origin, without its two distal corners.
  using Layout = std::array<std::array<double, 2>, kTaxels>;
  [[nodiscard]] static Layout layout(double pitch_mm) noexcept;

  // Non-RT. P validated by load_robot_params.
  TactileModel(const robot::TactileParams& p, std::uint64_t seed);

  [[nodiscard]] robot::TactileKind kind() const noexcept { return p_.kind; }

  // Taxel matrix (kind taxel_matrix). One fingertip pressed with NORMAL_FORCE_N (N, >= 0) at
  // (x_mm, y_mm) of its pad frame. RT.
  void taxels_rt(double normal_force_n, double x_mm, double y_mm, float out_kpa[kTaxels]) noexcept;
  // Every fingertip of HAND, each pressed at its pad's centre (the world reports no contact
  // point per fingertip). A fingertip not in contact reads the noise floor. RT.
  void taxels_rt(const WorldHand& hand, float out_kpa[kFingertips][kTaxels]) noexcept;
  // The calibrated force of one matrix (N): the sum of its pressures x taxel_area_mm2.
  [[nodiscard]] double taxel_force_n(const float kpa[kTaxels]) const noexcept;

  // PST sensors (kind pst): one sample of every fingertip after DT_S (s) of world time. RT.
  void pst_rt(const WorldHand& hand, double dt_s, float out_kpa[kFingertips]) noexcept;
  // One fingertip's sample (the sensors are independent). RT.
  [[nodiscard]] float pst_rt(int tip, double normal_force_n, double dt_s) noexcept;

  // Standard normal draw (Box-Muller on splitmix64). RT.
  [[nodiscard]] double gaussian() noexcept;

 private:
  robot::TactileParams p_;
  Layout layout_{};
  SplitMix64 rng_;
  double spare_ = 0;
  bool has_spare_ = false;
  std::array<double, kFingertips> pst_drift_kpa_{};     // accumulated drift
  std::array<double, kFingertips> pst_baseline_kpa_{};  // the high-pass's low-passed input
};

}  // namespace crease::world
