// The force controller's configuration: its parameters (README.md) and, from the robot's
// files (config/robot/), the hand's joint limits and its tactile calibration. Units: rad, s, N,
// N m/rad, kPa.
#pragma once

#include <array>
#include <cstdint>

#include "core/port_types/hand.h"
#include "plugins/robot_model/robot_layout.h"
#include "plugins/robot_model/robot_params.h"

namespace crease::force {

inline constexpr int kJoints = HandCommand::kJoints;
inline constexpr int kFingers = 5;       // ff mf rf lf th
inline constexpr int kForceFingers = 4;  // the thumb is never force controlled (seed 000 Eq. 6)

enum class OnBadInput : std::uint8_t { hold, retreat };

inline constexpr std::array<double, kJoints> filled(double v) noexcept {
  std::array<double, kJoints> a{};
  for (double& x : a) x = v;
  return a;
}

struct ForceConfig {
  robot::TactileKind sensor = robot::TactileKind::pst;  // pst: hand_state pressures; taxel_matrix: `tactile`
  double kpa_per_n = 10.0;       // PST calibration (robot YAML)
  double pst_highpass_s = 30.0;  // the PST electronics' high-pass (robot YAML); 0: not undone
  double taxel_area_mm2 = 11.0;  // taxel calibration (robot YAML)
  // Eq. 6: the per-joint gain modulation alpha_i (only the four fingers' J3 and J2), and k_P
  // (rad of target per N of error per s; per cycle: k_p x dt).
  std::array<double, kJoints> alpha{};
  double k_p = 2.0;
  std::array<double, kJoints> lower{}, upper{};  // the URDF's joint limits
  double max_flex_rad = 0.6;      // saturation: flexion beyond the force mode's starting pose
  double max_rate_rad_s = 1.0;    // every commanded joint, every mode
  double retreat_rad = 0.15;      // a retreat extends every finger's flexion joints by this
  // N m/rad per joint, until a posture goal sets others: `default_stiffness` for every joint,
  // `joint_stiffness` by name over it (a wrist held stiff while the fingers press softly).
  std::array<double, kJoints> default_stiffness = filled(2.0);
  double force_limit_n = 5.0;     // hard limit per fingertip: exceeded -> retreat, fault event
  int force_limit_samples = 3;    // ... on this many new samples of the finger in a row
  double max_goal_force_n = 4.0;  // goals above are refused (< force_limit_n)
  double settle_band = 0.05;      // |error| <= band x goal (and >= settle_band_n) ...
  double settle_band_n = 0.02;
  double settle_hold_s = 0.05;    // ... for this long: settled
  OnBadInput on_bad_input = OnBadInput::hold;
  int stale_cycles = 3;           // hand_state: cycles without a fresh ok status tolerated
  std::int64_t max_tactile_age_ns = 20'000'000;
  std::int64_t max_contact_age_ns = 5'000'000;
  double baseline_time_constant_s = 0.5;  // PST tare while a finger is out of contact
  bool anti_windup = true;        // false only to show what it prevents (tests)
  // start: limp (true): from the first healthy hand_state the hand is commanded enable 0 (zero
  // stiffness, what the driver does unasked) until a first goal is accepted; hold (false): held
  // where it is at default_stiffness from that first state.
  bool start_limp = true;
};

}  // namespace crease::force
