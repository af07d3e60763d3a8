// C_contact of seed 000 (Eq. 5) for one hand: contact when the selected joints deviate from
// their relaxed pose, ||theta - theta_ref||_P > Delta theta_max, OR'ed with tactile contact
// (a fingertip's pressure above its tared baseline).
//
//  - Arming: theta_ref is captured once the hand has settled (every selected joint, and its
//    commanded target when hand_command is read, within settle_band_rad for settle_cycles) while
//    nothing touches: the joints' mean over that window. The window also measures the joints'
//    noise, sqrt(sum_j w_j var_j) (the P-norm a still hand's readings scatter by), and the
//    thresholds in use are enter = max(enter_rad, noise_factor x noise), exit scaled with it
//    (published as threshold_rad): a low enter_rad, down at the sensor's resolution, holds on
//    joints that read exactly and rises by itself on noisy ones rather than fire on the noise.
//    Noise too rare for the window (a joint near a quantisation step flickering now and then)
//    shows as a spike the debounce rejected: out of contact, each rejected joint spike raises
//    the thresholds in use to spike_margin x its peak deviation (until the next arming).
//    The tactile baselines are tared over that same window, then follow the
//    readings slowly (baseline_time_constant_s) while there is no contact (drift). A posture
//    change of more than rearm_rad in the commanded targets while out of contact disarms: the
//    hand settles again and a new theta_ref is taken.
//  - Deviation: (theta - theta_ref) - (target - target_ref) per joint (the hand's compliant
//    deflection away from the relaxed pose under the current command, so that the force
//    controller flexing the fingers in contact is not read as more contact), P-weighted:
//    sqrt(sum_j w_j d_j^2), over the hand and per finger.
//  - Hysteresis: the enter thresholds while out of contact, the lower exit ones while in.
//    Debounce: an onset needs one test (the joints', or one fingertip's tactile test) to fire
//    debounce_cycles cycles in a row; a release needs every test quiet that long (1: no
//    debounce). Per test, so that noise on two fingertips in turn does not add up. Fingers: those whose tactile test fired, and those whose own
//    deviation exceeds half the enter threshold (else the most deviated) when the joints fired.
//  - Bad input: hand_state health fault, or no fresh healthy status for more than stale_cycles
//    (degraded counts as not fresh), or taxels older than max_tactile_age_ns: healthy = 0, the
//    decision is frozen (no onset, no release on stale data); out of contact it also disarms.
// Angles rad, pressures kPa (a taxel fingertip: the sum of its 34 taxels), times ns. RT except
// the constructor.
#pragma once

#include <array>
#include <cstdint>

#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/tactile.h"

namespace crease::contact {

inline constexpr int kJoints = HandState::kJoints;
inline constexpr int kFingers = ContactState::kFingers;

enum class TactileSource : std::uint8_t { none, pst, taxels };

struct ContactConfig {
  std::array<double, kJoints> weight{};  // P's diagonal; 0: not selected
  double enter_rad = 0.002;              // Delta theta_max
  double exit_rad = 0.001;
  int debounce_cycles = 2;
  double noise_factor = 3.0;  // enter >= this x the joints' measured noise (0: enter_rad alone)
  double spike_margin = 1.5;  // enter >= this x a rejected spike's deviation (0: not raised)
  int settle_cycles = 50;
  double settle_band_rad = 0.001;
  double rearm_rad = 0.01;
  TactileSource tactile = TactileSource::none;
  double tactile_enter_kpa = 0.045;  // 4.5 x the PST noise (0.01 kPa): 4.5 mN
  double tactile_exit_kpa = 0.02;
  double baseline_time_constant_s = 1.0;
  int stale_cycles = 3;
  std::int64_t max_tactile_age_ns = 20'000'000;
};

struct ContactInputs {
  std::int64_t time_ns = 0;
  double dt_s = 0.001;
  const HandState* hand = nullptr;  // null: never received
  bool hand_new = false;            // a new value this cycle
  const HandCommand* command = nullptr;  // optional: the targets the hand is commanded to
  const Tactile* tactile = nullptr;      // the taxel matrix (TactileSource::taxels)
};

class ContactDetector {
 public:
  // Everything a hot-swap carries over (trivially copyable).
  struct State {
    std::array<float, kJoints> theta_ref{}, target_ref{}, window_theta{}, window_target{};
    std::array<double, kFingers> baseline_kpa{}, window_sum_kpa{};
    std::array<double, kFingers> last_kpa{};  // each PST sensor's last sample (hand_state's come per cycle)
    std::uint8_t kpa_seen = 0;                // bit f: sensor f has sent a sample
    std::array<double, kJoints> window_sum_rad{}, window_sum2_rad{};  // of theta - window_theta
    double enter_rad = 0, exit_rad = 0;  // the thresholds in use (set when it arms)
    double noise_rad = 0;                // the joints' noise measured when it armed
    double spike_rad = 0;                // the peak deviation of the joints' current run
    std::uint64_t spikes = 0;            // joint spikes the debounce rejected
    std::int64_t since_ns = 0;
    std::uint64_t onsets = 0;
    std::int32_t window_cycles = 0;
    std::int32_t debounce = 0;     // quiet cycles in a row while in contact
    std::int32_t joint_run = 0;    // cycles in a row the joints' test fired
    std::array<std::int32_t, kFingers> tactile_run{};  // per fingertip, its tactile test
    std::int32_t stale = 0;
    std::uint8_t armed = 0, in_contact = 0, fingers = 0, source = contact_none;
  };

  explicit ContactDetector(const ContactConfig& c) : c_(c) {}

  // One cycle. Fills OUT; returns true when the debounced contact changed (then EVENT holds it).
  bool step_rt(const ContactInputs& in, ContactState& out, ContactEvent& event) noexcept;

  [[nodiscard]] const State& state() const noexcept { return s_; }
  void restore(const State& s) noexcept { s_ = s; }
  [[nodiscard]] const ContactConfig& config() const noexcept { return c_; }

 private:
  [[nodiscard]] bool hand_healthy_rt(const ContactInputs& in) noexcept;
  [[nodiscard]] bool tactile_healthy(const ContactInputs& in) const noexcept;
  // The fingertips' pressures this cycle. A PST sensor without a sample this cycle
  // (pressure_valid is per cycle: its frame did not come in) reads as its last sample: no sample
  // is not no pressure (it broke the tactile test's run, so a press whose frames came every
  // other cycle never debounced into a contact).
  void pressures(const ContactInputs& in, std::array<double, kFingers>& kpa, std::uint8_t& valid) noexcept;
  void settle_rt(const ContactInputs& in, const std::array<double, kFingers>& kpa) noexcept;

  ContactConfig c_;
  State s_;
};

}  // namespace crease::contact
