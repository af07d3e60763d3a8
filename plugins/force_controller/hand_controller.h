// One hand's command stage (plugins/force_controller): the modes posture, hold and force
// (C_force, seed 000 Eq. 6) and the safe action retreat, turned into one HandCommand a cycle.
//
// Forces (N): the left hand's PST pressure above its tare (which follows the sensor while the
// finger touches nothing) / kpa_per_n, the sensor's high-pass undone while pressing
// (x = y + integral y dt / tau); the right hand's taxel sum x taxel_area_mm2 / 1000.
// Force mode, per finger f in force control (never the thumb):
//   u_f += k_P (f_target - f_f) dt,   target_i = base_i + alpha_i u_f  (i: f's flexion joints)
// i.e. Eq. 6's delta theta_i = alpha_i k_P (f_target - f_current) per cycle, with base the
// commanded targets when force mode began. Saturation: u_f is confined so that every flexion
// joint stays within its URDF limits and within max_flex_rad of base (anti-windup: the
// integrator stops at the bound, it does not wind up behind it; anti_windup = false keeps
// integrating and only clamps the output, to show the difference). Rate: |delta u_f| is capped
// so no joint moves faster than max_rate_rad_s. f_target ramps linearly from the force measured
// when the goal arrived to the goal's over its ramp_s. Settled: every finger's |error| within
// max(settle_band x goal, settle_band_n) for settle_hold_s.
//
// Bumpless: every mode starts from the targets commanded in the last cycle (a posture ramps
// from them, force adds its offsets to them, hold keeps them), and every commanded joint is
// rate limited to max_rate_rad_s, so no switch makes the commanded targets jump.
// Safety, every cycle: hand_state with health fault, or no fresh ok status for more than
// stale_cycles (degraded counts as not fresh); the taxel matrix (right hand) with health fault
// or older than max_tactile_age_ns: the controller stops adding force and holds or retreats
// (on_bad_input), reporting why; goals are refused while it lasts, and when the inputs come
// back it stays where it is until a new goal arrives (no stale plan resumes). A fingertip
// measured above force_limit_n: retreat and a force_limit_fault event, whatever the mode. A
// retreat extends every finger's flexion joints by retreat_rad from where force control began
// (or from the commanded targets), at the rate limit.
// Start (start_limp): from the first healthy hand_state until a first goal is accepted the
// command is enable 0 (the hand limp, zero stiffness: what the driver does unasked) with the
// measured angles as targets; nothing retreats or holds meanwhile (a force-limit fault is still
// raised). The accepted goal starts from the angles measured then, at default_stiffness (or the
// posture goal's), so the hand is taken over where it lies.
// RT: step_rt and submit_rt; the constructor is not.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/hand_control.h"
#include "core/port_types/hand_goal.h"
#include "core/port_types/tactile.h"
#include "plugins/force_controller/force_config.h"

namespace crease::force {

struct ForceInputs {
  std::int64_t time_ns = 0;
  double dt_s = 0.001;
  const HandState* hand = nullptr;  // null: none received yet
  bool hand_new = false;
  const Tactile* tactile = nullptr;        // the taxel side
  const ContactState* contact = nullptr;   // optional (PST tare, the fingers in contact)
};

class HandController {
 public:
  static constexpr int kMaxEvents = 4;

  // Everything a hot-swap carries (trivially copyable).
  struct State {
    std::array<float, kJoints> cmd{}, stiffness{};
    std::array<float, kJoints> base{};          // force mode's starting targets
    std::array<float, kJoints> from{}, to{};    // posture ramp, retreat target
    std::array<double, kForceFingers> u{}, u_lo{}, u_hi{};
    std::array<double, kFingers> baseline_kpa{};
    std::array<double, kFingers>
        highpass_kpa{};  // the PST high-pass's low-passed pressure (what it takes away)
    std::array<double, kFingers> pst_gap_s{};     // since each PST sensor's last sample (s)
    std::array<std::int32_t, kFingers>
        over_limit{};                           // each finger's samples over the limit in a row
    std::int64_t tactile_ns = 0;                // the taxel matrix sample last measured
    double ramp_t = 0, ramp_T = 0;              // posture or force ramp: elapsed, duration (s)
    double f_from = 0, f_goal = 0, f_target = 0;
    double in_band_s = 0;
    std::int64_t settled_since_ns = 0;
    std::int64_t in_band_since_ns = 0;
    std::uint64_t goals_accepted = 0, goals_refused = 0, inhibits = 0;
    std::int32_t stale = 0;
    std::uint32_t goal_id = 0;
    HandMode mode = HandMode::hold;
    HandInhibit inhibit = HandInhibit::none;
    GoalRefusal last_refusal = GoalRefusal::none;
    std::uint8_t fingers = 0;
    std::uint8_t saturated = 0;
    std::uint8_t commanding = 0;   // a first hand_state set the command
    std::uint8_t limp = 0;         // enable 0 commanded, the targets following the hand (start: limp)
    std::uint8_t force_mode_base = 0;  // 1: base holds force mode's start (for a retreat)
  };

  explicit HandController(const ForceConfig& c) : c_(c) {}

  // A goal from `hand_goal`, applied at this cycle's step. Returns false when refused (counted).
  bool submit_rt(const HandGoal& g, const ForceInputs& in) noexcept;

  // One cycle: inputs checked, forces measured, the mode's targets, the command and status.
  // Returns true when COMMAND is to be written (a hand_state has been seen).
  bool step_rt(const ForceInputs& in, HandCommand& command, HandControlStatus& status) noexcept;

  // Events of the goals submitted and the steps since the last clear (at most kMaxEvents; more
  // are counted in events_lost()).
  [[nodiscard]] std::span<const HandControlEvent> events() const noexcept { return {ev_.data(), std::size_t(n_ev_)}; }
  void clear_events() noexcept { n_ev_ = 0; }
  [[nodiscard]] std::uint64_t events_lost() const noexcept { return events_lost_; }

  // The calibrated force of each fingertip this cycle (N).
  [[nodiscard]] const std::array<double, kFingers>& forces() const noexcept { return f_; }
  [[nodiscard]] const State& state() const noexcept { return s_; }
  void restore(const State& s) noexcept { s_ = s; }
  [[nodiscard]] const ForceConfig& config() const noexcept { return c_; }
  // k_P changed while running (a tunable), rad per N per s.
  void set_k_p(double k_p) noexcept { c_.k_p = k_p; }

 private:
  [[nodiscard]] HandInhibit check_inputs_rt(const ForceInputs& in) noexcept;
  // The fingertip forces f_ from this cycle's samples; returns the fingers with a new sample.
  std::uint8_t measure_rt(const ForceInputs& in) noexcept;
  void enter_force_rt(std::uint8_t fingers, double force_n, double ramp_s) noexcept;
  void enter_retreat_rt() noexcept;
  void force_step_rt(double dt) noexcept;
  void settle_rt(const ForceInputs& in) noexcept;
  void push(HandControlEvent::Kind k, std::int64_t t, float value = 0, std::uint8_t finger = 0) noexcept;
  [[nodiscard]] bool inputs_bad(const ForceInputs& in) const noexcept;

  ForceConfig c_;
  State s_;
  std::array<double, kFingers> f_{};
  std::array<HandControlEvent, kMaxEvents> ev_{};
  int n_ev_ = 0;
  std::uint64_t events_lost_ = 0;
};

}  // namespace crease::force
