#include "plugins/force_controller/hand_controller.h"

#include <algorithm>
#include <cmath>

namespace crease::force {
namespace {

constexpr std::size_t sz(int i) noexcept { return static_cast<std::size_t>(i); }

bool finite_goal(const HandGoal& g) noexcept {
  if (!std::isfinite(g.force_n) || !std::isfinite(g.ramp_s)) return false;
  for (int j = 0; j < HandGoal::kJoints; ++j)
    if (!std::isfinite(g.target_rad[j]) || !std::isfinite(g.stiffness_nm_per_rad[j])) return false;
  return true;
}

bool contact_fresh(const ForceInputs& in, std::int64_t max_age_ns) noexcept {
  return in.contact != nullptr && in.contact->healthy != 0 && in.time_ns - in.contact->timestamp_ns <= max_age_ns;
}

}  // namespace

void HandController::push(HandControlEvent::Kind k, std::int64_t t, float value, std::uint8_t finger) noexcept {
  if (n_ev_ >= kMaxEvents) {
    ++events_lost_;
    return;
  }
  HandControlEvent& e = ev_[sz(n_ev_++)];
  e.timestamp_ns = t;
  e.kind = k;
  e.value = value;
  e.mode = s_.mode;
  e.inhibit = s_.inhibit;
  e.finger = finger;
}

bool HandController::inputs_bad(const ForceInputs& in) const noexcept {
  if (in.hand == nullptr || in.hand->health == DeviceHealth::fault || s_.stale > c_.stale_cycles) return true;
  if (c_.sensor == robot::TactileKind::taxel_matrix) {
    if (in.tactile == nullptr || in.tactile->health == DeviceHealth::fault) return true;
    if (in.time_ns - in.tactile->timestamp_ns > c_.max_tactile_age_ns) return true;
  }
  return false;
}

HandInhibit HandController::check_inputs_rt(const ForceInputs& in) noexcept {
  if (in.hand == nullptr) return HandInhibit::hand_state_stale;
  if (in.hand->health == DeviceHealth::fault) {
    s_.stale = c_.stale_cycles + 1;
    return HandInhibit::hand_state_fault;
  }
  const bool fresh = in.hand_new && in.hand->fresh != 0 && in.hand->health == DeviceHealth::ok;
  s_.stale = fresh ? 0 : std::min(s_.stale + 1, c_.stale_cycles + 1);
  if (s_.stale > c_.stale_cycles) return HandInhibit::hand_state_stale;
  if (c_.sensor == robot::TactileKind::taxel_matrix) {
    if (in.tactile == nullptr || in.tactile->health == DeviceHealth::fault) return HandInhibit::tactile_fault;
    if (in.time_ns - in.tactile->timestamp_ns > c_.max_tactile_age_ns) return HandInhibit::tactile_stale;
  }
  return HandInhibit::none;
}

std::uint8_t HandController::measure_rt(const ForceInputs& in) noexcept {
  if (c_.sensor == robot::TactileKind::taxel_matrix) {
    for (int f = 0; f < kFingers; ++f) {
      double sum = 0;
      if ((in.tactile->valid & (1u << f)) != 0)
        for (float p : in.tactile->pressure_kpa[f]) sum += p;
      f_[sz(f)] = sum * c_.taxel_area_mm2 / 1000.0;
    }
    const bool new_sample = in.tactile->timestamp_ns != s_.tactile_ns;
    s_.tactile_ns = in.tactile->timestamp_ns;
    return new_sample ? in.tactile->valid : 0;
  }
  // PST: pressure above the tare, which follows the sensor while the finger touches nothing.
  // The electronics' high-pass (time constant pst_highpass_s) bleeds a held pressure away: its
  // low-passed copy b of the cavity pressure, db/dt = y / tau with y the output, is tracked as
  // highpass_kpa and added back (x = y + b). It is not forgotten when the finger lets go: b then
  // decays with tau, and the output undershoots by it, clipped at 0 on the wire (u16); a reading
  // of 0 tells nothing of b, which is then taken to decay as with nothing pressed. Forgetting it
  // (as before) made the next press read low by what was left: a fixing hand pressed 3.2 N for
  // a 2 N goal after a 35 s press. A clipped reading measures 0 N (the force lies somewhere
  // under b; the force loop presses on until the sensor reads again), and leaves the tare as is.
  // A cycle without a sample of a sensor (its frame did not come in this cycle: pressure_valid
  // is per cycle) holds that finger's force as last measured, and the next sample covers the
  // time since its last one: no sample is not no force (a reading of 0 N mid-press made the force
  // loop push and reset its settling, on a loaded machine every few cycles). A hand_state gone
  // stale altogether is check_inputs_rt's: force stops being added.
  std::uint8_t sampled = 0;
  const bool contact = contact_fresh(in, c_.max_contact_age_ns);
  for (int f = 0; f < kFingers; ++f) {
    s_.pst_gap_s[sz(f)] += in.dt_s;
    if ((in.hand->pressure_valid & (1u << f)) == 0) continue;
    sampled |= static_cast<std::uint8_t>(1u << f);
    const double dt = s_.pst_gap_s[sz(f)];
    s_.pst_gap_s[sz(f)] = 0;
    const double a = std::min(1.0, dt / c_.baseline_time_constant_s);
    const double p = in.hand->pressure_kpa[f];
    const bool pressed = (s_.mode == HandMode::force && (s_.fingers & (1u << f)) != 0) ||
                         (contact && (in.contact->fingers & (1u << f)) != 0);
    const bool reads = p > 0;  // not clipped at the wire's 0
    double& b = s_.highpass_kpa[sz(f)];
    const double above = p - s_.baseline_kpa[sz(f)];
    if (contact && !pressed && reads)
      s_.baseline_kpa[sz(f)] += a * (p + b - s_.baseline_kpa[sz(f)]);
    if (c_.pst_highpass_s > 0) b += (reads ? above : -b) * std::min(1.0, dt / c_.pst_highpass_s);
    f_[sz(f)] = reads ? std::max(0.0, (above + b) / c_.kpa_per_n) : 0.0;
  }
  return sampled;
}

bool HandController::submit_rt(const HandGoal& g, const ForceInputs& in) noexcept {
  auto refuse = [&](GoalRefusal why) {
    ++s_.goals_refused;
    s_.last_refusal = why;
    push(HandControlEvent::goal_refused, in.time_ns, static_cast<float>(why));
    return false;
  };
  if (!finite_goal(g)) return refuse(GoalRefusal::non_finite);
  if (g.mode != HandMode::posture && g.mode != HandMode::hold && g.mode != HandMode::force)
    return refuse(GoalRefusal::bad_mode);
  if (g.ramp_s < 0 || g.ramp_s > 60 || g.force_n < 0 || g.force_n > c_.max_goal_force_n) return refuse(GoalRefusal::out_of_range);
  if (g.mode == HandMode::posture && g.set_stiffness != 0)
    for (float k : g.stiffness_nm_per_rad)
      if (k < 0 || k > 655.35f) return refuse(GoalRefusal::out_of_range);
  if (s_.commanding == 0 || inputs_bad(in)) return refuse(GoalRefusal::inputs_bad);
  if (s_.inhibit == HandInhibit::force_limit)
    for (double f : f_)
      if (f > c_.force_limit_n) return refuse(GoalRefusal::inputs_bad);
  std::uint8_t fingers = 0;
  if (g.mode == HandMode::force) {
    fingers = g.fingers & 0x0F;
    if (fingers == 0 && contact_fresh(in, c_.max_contact_age_ns)) fingers = in.contact->fingers & 0x0F;
    if (fingers == 0) return refuse(GoalRefusal::no_fingers);
  }

  ++s_.goals_accepted;
  s_.goal_id = g.id;
  s_.inhibit = HandInhibit::none;
  if (s_.limp != 0) {  // taken over where the limp hand lies
    for (int j = 0; j < kJoints; ++j) s_.cmd[sz(j)] = in.hand->position_rad[j];
    s_.limp = 0;
  }
  switch (g.mode) {
    case HandMode::posture:
      s_.from = s_.cmd;
      for (int j = 0; j < kJoints; ++j)
        s_.to[sz(j)] = static_cast<float>(std::clamp<double>(g.target_rad[j], c_.lower[sz(j)], c_.upper[sz(j)]));
      if (g.set_stiffness != 0)
        for (int j = 0; j < kJoints; ++j) s_.stiffness[sz(j)] = g.stiffness_nm_per_rad[j];
      s_.ramp_t = 0;
      s_.ramp_T = g.ramp_s;
      s_.mode = HandMode::posture;
      s_.force_mode_base = 0;
      break;
    case HandMode::hold:
      s_.mode = HandMode::hold;
      break;
    default:
      enter_force_rt(fingers, g.force_n, g.ramp_s);
      break;
  }
  s_.settled_since_ns = 0;
  s_.in_band_since_ns = 0;
  push(HandControlEvent::mode_changed, in.time_ns);
  return true;
}

void HandController::enter_force_rt(std::uint8_t fingers, double force_n, double ramp_s) noexcept {
  const bool continuing = s_.mode == HandMode::force;
  double f_now = 0;
  int n = 0;
  for (int f = 0; f < kForceFingers; ++f)
    if ((fingers & (1u << f)) != 0) {
      f_now += f_[sz(f)];
      ++n;
    }
  // A new target while pressing ramps from the current target; otherwise from what is measured.
  s_.f_from = continuing ? s_.f_target : (n > 0 ? f_now / n : 0.0);
  s_.f_goal = force_n;
  s_.f_target = s_.f_from;
  s_.ramp_t = 0;
  s_.ramp_T = ramp_s;
  for (int f = 0; f < kForceFingers; ++f) {
    const bool was = continuing && (s_.fingers & (1u << f)) != 0;
    if (was) continue;  // keeps its base and integrator: no jump
    s_.u[sz(f)] = 0;
    double hi = 1e9, lo = -1e9;
    for (int j = 0; j < kJoints; ++j) {
      if (robot::finger_of_hand_joint(j) != f || !robot::is_finger_flexion_joint(j)) continue;
      s_.base[sz(j)] = s_.cmd[sz(j)];
      const double a = c_.alpha[sz(j)];
      if (a <= 0) continue;
      hi = std::min(hi, std::min(c_.max_flex_rad, c_.upper[sz(j)] - s_.base[sz(j)]) / a);
      lo = std::max(lo, std::max(-c_.max_flex_rad, c_.lower[sz(j)] - s_.base[sz(j)]) / a);
    }
    s_.u_hi[sz(f)] = std::max(0.0, hi > 1e8 ? 0.0 : hi);
    s_.u_lo[sz(f)] = std::min(0.0, lo < -1e8 ? 0.0 : lo);
  }
  if (!continuing) s_.to = s_.cmd;  // the joints force control does not move stay where they are
  s_.fingers = fingers;
  s_.saturated = 0;
  s_.mode = HandMode::force;
  s_.force_mode_base = 1;
}

void HandController::enter_retreat_rt() noexcept {
  s_.to = s_.cmd;
  for (int j = 0; j < kJoints; ++j) {
    const int f = robot::finger_of_hand_joint(j);
    if (f < 0 || f >= kForceFingers || !robot::is_finger_flexion_joint(j)) continue;
    const double origin = s_.force_mode_base != 0 ? std::min(s_.base[sz(j)], s_.cmd[sz(j)]) : s_.cmd[sz(j)];
    s_.to[sz(j)] = static_cast<float>(std::clamp(origin - c_.retreat_rad, c_.lower[sz(j)], c_.upper[sz(j)]));
  }
  s_.mode = HandMode::retreat;
  s_.settled_since_ns = 0;
}

void HandController::force_step_rt(double dt) noexcept {
  s_.ramp_t += dt;
  const double a = s_.ramp_T > 0 ? std::min(1.0, s_.ramp_t / s_.ramp_T) : 1.0;
  s_.f_target = s_.f_from + (s_.f_goal - s_.f_from) * a;
  s_.saturated = 0;
  for (int f = 0; f < kForceFingers; ++f) {
    if ((s_.fingers & (1u << f)) == 0) continue;
    double alpha_max = 0;
    for (int j = 0; j < kJoints; ++j)
      if (robot::finger_of_hand_joint(j) == f && robot::is_finger_flexion_joint(j))
        alpha_max = std::max(alpha_max, c_.alpha[sz(j)]);
    if (alpha_max <= 0) continue;
    // Eq. 6 per cycle, the step capped to the rate limit.
    const double cap = c_.max_rate_rad_s * dt / alpha_max;
    double& u = s_.u[sz(f)];
    u += std::clamp(c_.k_p * (s_.f_target - f_[sz(f)]) * dt, -cap, cap);
    const bool over = u >= s_.u_hi[sz(f)] || u <= s_.u_lo[sz(f)];
    if (over) s_.saturated |= static_cast<std::uint8_t>(1u << f);
    if (c_.anti_windup) u = std::clamp(u, s_.u_lo[sz(f)], s_.u_hi[sz(f)]);
    const double uc = std::clamp(u, s_.u_lo[sz(f)], s_.u_hi[sz(f)]);
    for (int j = 0; j < kJoints; ++j)
      if (robot::finger_of_hand_joint(j) == f && robot::is_finger_flexion_joint(j))
        s_.to[sz(j)] = static_cast<float>(s_.base[sz(j)] + c_.alpha[sz(j)] * uc);
  }
}

void HandController::settle_rt(const ForceInputs& in) noexcept {
  if (s_.mode != HandMode::force || s_.ramp_t < s_.ramp_T) {
    s_.in_band_since_ns = s_.settled_since_ns = 0;
    return;
  }
  const double band = std::max(c_.settle_band * s_.f_goal, c_.settle_band_n);
  bool in_band = true;
  for (int f = 0; f < kForceFingers; ++f)
    if ((s_.fingers & (1u << f)) != 0 && std::fabs(s_.f_goal - f_[sz(f)]) > band) in_band = false;
  if (!in_band) {
    s_.in_band_since_ns = s_.settled_since_ns = 0;
    return;
  }
  if (s_.in_band_since_ns == 0) s_.in_band_since_ns = in.time_ns;
  if (static_cast<double>(in.time_ns - s_.in_band_since_ns) * 1e-9 >= c_.settle_hold_s)
    s_.settled_since_ns = s_.in_band_since_ns;
}

bool HandController::step_rt(const ForceInputs& in, HandCommand& command, HandControlStatus& status) noexcept {
  const HandInhibit bad = check_inputs_rt(in);
  if (s_.commanding == 0 && in.hand != nullptr && bad == HandInhibit::none) {
    // The first healthy state: hold the hand where it is (no jump), tare the PST sensors.
    for (int j = 0; j < kJoints; ++j) {
      s_.cmd[sz(j)] = in.hand->position_rad[j];
      s_.stiffness[sz(j)] = static_cast<float>(c_.default_stiffness[sz(j)]);
    }
    for (int f = 0; f < kFingers; ++f) s_.baseline_kpa[sz(f)] = in.hand->pressure_kpa[f];
    s_.commanding = 1;
    s_.mode = HandMode::hold;
    s_.limp = c_.start_limp ? 1 : 0;
  }
  if (s_.limp != 0 && in.hand != nullptr && bad == HandInhibit::none)  // follow the limp hand
    for (int j = 0; j < kJoints; ++j) s_.cmd[sz(j)] = in.hand->position_rad[j];
  const std::array<float, kJoints> before = s_.cmd;
  if (s_.commanding != 0) {
    if (bad == HandInhibit::none) {
      const std::uint8_t sampled = measure_rt(in);
      for (int f = 0; f < kFingers; ++f) {
        // Over the limit on force_limit_samples new samples in a row: the world's contacts (and a
        // real fingertip's knock) can spike for one sample (a trial: 7.1 N for a step on a finger
        // pressing 2 N, 2.3 N the next), which is not an overload to retreat from.
        auto& run = s_.over_limit[sz(f)];
        if ((sampled & (1u << f)) != 0) run = f_[sz(f)] > c_.force_limit_n ? run + 1 : 0;
        if (run < c_.force_limit_samples || s_.inhibit == HandInhibit::force_limit) continue;
        s_.inhibit = HandInhibit::force_limit;  // whatever the mode or target
        ++s_.inhibits;
        if (s_.limp == 0) enter_retreat_rt();  // a limp hand pushes nothing back
        push(HandControlEvent::force_limit_fault, in.time_ns, static_cast<float>(f_[sz(f)]), static_cast<std::uint8_t>(f));
      }
    } else if (s_.inhibit != bad && s_.inhibit != HandInhibit::force_limit) {
      s_.inhibit = bad;  // stop adding force: hold or retreat
      ++s_.inhibits;
      if (c_.on_bad_input == OnBadInput::retreat && s_.limp == 0) {
        if (s_.mode != HandMode::retreat) enter_retreat_rt();
      } else if (s_.mode != HandMode::retreat) {
        s_.mode = HandMode::hold;
      }
      push(HandControlEvent::inhibited, in.time_ns);
    }

    std::array<float, kJoints> desired = s_.cmd;
    switch (s_.mode) {
      case HandMode::posture: {
        s_.ramp_t += in.dt_s;
        const double a = s_.ramp_T > 0 ? std::min(1.0, s_.ramp_t / s_.ramp_T) : 1.0;
        for (int j = 0; j < kJoints; ++j)
          desired[sz(j)] = static_cast<float>(s_.from[sz(j)] + a * (s_.to[sz(j)] - s_.from[sz(j)]));
        break;
      }
      case HandMode::force:
        force_step_rt(in.dt_s);
        desired = s_.to;
        break;
      case HandMode::hold:
        break;
      case HandMode::retreat:
        desired = s_.to;
        break;
    }
    const double step = c_.max_rate_rad_s * in.dt_s;
    for (int j = 0; j < kJoints; ++j)
      s_.cmd[sz(j)] += static_cast<float>(std::clamp<double>(desired[sz(j)] - s_.cmd[sz(j)], -step, step));
    settle_rt(in);
  }

  float max_step = 0;
  for (int j = 0; j < kJoints; ++j) max_step = std::max(max_step, std::fabs(s_.cmd[sz(j)] - before[sz(j)]));
  status = HandControlStatus{};
  status.timestamp_ns = in.time_ns;
  status.settled_since_ns = s_.settled_since_ns;
  status.goals_accepted = s_.goals_accepted;
  status.goals_refused = s_.goals_refused;
  status.inhibits = s_.inhibits;
  status.force_target_n = static_cast<float>(s_.mode == HandMode::force ? s_.f_target : 0.0);
  status.force_goal_n = static_cast<float>(s_.mode == HandMode::force ? s_.f_goal : 0.0);
  for (int f = 0; f < kFingers; ++f) status.force_n[f] = static_cast<float>(f_[sz(f)]);
  status.max_step_rad = max_step;
  status.goal_id = s_.goal_id;
  status.mode = s_.mode;
  status.inhibit = s_.inhibit;
  status.fingers = s_.mode == HandMode::force ? s_.fingers : 0;
  status.settled = s_.settled_since_ns != 0 ? 1 : 0;
  status.saturated = s_.saturated;
  status.commanding = s_.commanding;
  status.limp = s_.limp;
  status.last_refusal = static_cast<std::uint8_t>(s_.last_refusal);
  if (s_.commanding == 0) return false;
  command.timestamp_ns = in.time_ns;
  for (int j = 0; j < kJoints; ++j) {
    command.target_rad[j] = s_.cmd[sz(j)];
    command.stiffness_nm_per_rad[j] = s_.limp != 0 ? 0.0f : s_.stiffness[sz(j)];
  }
  command.enable = s_.limp != 0 ? 0 : 1;
  return true;
}

}  // namespace crease::force
