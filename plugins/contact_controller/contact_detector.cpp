#include "plugins/contact_controller/contact_detector.h"

#include <algorithm>
#include <cmath>

#include "plugins/robot_model/robot_layout.h"

namespace crease::contact {

bool ContactDetector::hand_healthy_rt(const ContactInputs& in) noexcept {
  if (in.hand == nullptr || in.hand->health == DeviceHealth::fault) {
    s_.stale = c_.stale_cycles + 1;
    return false;
  }
  const bool fresh = in.hand_new && in.hand->fresh != 0 && in.hand->health == DeviceHealth::ok;
  s_.stale = fresh ? 0 : std::min(s_.stale + 1, c_.stale_cycles + 1);
  return s_.stale <= c_.stale_cycles;
}

bool ContactDetector::tactile_healthy(const ContactInputs& in) const noexcept {
  if (c_.tactile != TactileSource::taxels) return true;
  if (in.tactile == nullptr || in.tactile->health == DeviceHealth::fault) return false;
  return in.time_ns - in.tactile->timestamp_ns <= c_.max_tactile_age_ns;
}

void ContactDetector::pressures(const ContactInputs& in, std::array<double, kFingers>& kpa,
                                std::uint8_t& valid) noexcept {
  kpa.fill(0.0);
  valid = 0;
  if (c_.tactile == TactileSource::pst && in.hand != nullptr) {
    for (int f = 0; f < kFingers; ++f) {
      const auto fs = static_cast<std::size_t>(f);
      if ((in.hand->pressure_valid & (1u << f)) != 0) {
        s_.last_kpa[fs] = in.hand->pressure_kpa[f];
        s_.kpa_seen = static_cast<std::uint8_t>(s_.kpa_seen | (1u << f));
      }
      kpa[fs] = s_.last_kpa[fs];
    }
    valid = s_.kpa_seen;
  } else if (c_.tactile == TactileSource::taxels && in.tactile != nullptr) {
    for (int f = 0; f < kFingers; ++f) {
      double sum = 0;
      for (float p : in.tactile->pressure_kpa[f]) sum += p;
      kpa[static_cast<std::size_t>(f)] = sum;
    }
    valid = in.tactile->valid;
  }
}

void ContactDetector::settle_rt(const ContactInputs& in, const std::array<double, kFingers>& kpa) noexcept {
  const HandState& h = *in.hand;
  bool still = s_.window_cycles > 0;
  for (int j = 0; j < kJoints && still; ++j) {
    if (c_.weight[static_cast<std::size_t>(j)] <= 0) continue;
    const auto js = static_cast<std::size_t>(j);
    if (std::fabs(h.position_rad[j] - s_.window_theta[js]) > c_.settle_band_rad) still = false;
    if (in.command != nullptr && std::fabs(in.command->target_rad[j] - s_.window_target[js]) > c_.settle_band_rad)
      still = false;
  }
  if (!still) {  // (re)start the window here
    for (int j = 0; j < kJoints; ++j) {
      s_.window_theta[static_cast<std::size_t>(j)] = h.position_rad[j];
      s_.window_target[static_cast<std::size_t>(j)] = in.command != nullptr ? in.command->target_rad[j] : 0.0f;
    }
    s_.window_sum_kpa.fill(0.0);
    s_.window_sum_rad.fill(0.0);
    s_.window_sum2_rad.fill(0.0);
    s_.window_cycles = 0;
  }
  for (int f = 0; f < kFingers; ++f) s_.window_sum_kpa[static_cast<std::size_t>(f)] += kpa[static_cast<std::size_t>(f)];
  for (int j = 0; j < kJoints; ++j) {
    const auto js = static_cast<std::size_t>(j);
    const double x = static_cast<double>(h.position_rad[j]) - s_.window_theta[js];
    s_.window_sum_rad[js] += x;
    s_.window_sum2_rad[js] += x * x;
  }
  if (++s_.window_cycles < c_.settle_cycles) return;
  const double n = s_.window_cycles;
  double noise2 = 0;
  for (int j = 0; j < kJoints; ++j) {
    const auto js = static_cast<std::size_t>(j);
    const double mean = s_.window_sum_rad[js] / n;
    s_.theta_ref[js] = static_cast<float>(s_.window_theta[js] + mean);  // the window's mean
    s_.target_ref[js] = in.command != nullptr ? in.command->target_rad[j] : 0.0f;
    noise2 += c_.weight[js] * std::max(0.0, s_.window_sum2_rad[js] / n - mean * mean);
  }
  s_.noise_rad = std::sqrt(noise2);
  s_.enter_rad = std::max(c_.enter_rad, c_.noise_factor * s_.noise_rad);
  s_.exit_rad = c_.exit_rad * (s_.enter_rad / c_.enter_rad);
  s_.spike_rad = 0;
  for (int f = 0; f < kFingers; ++f) {
    const auto fs = static_cast<std::size_t>(f);
    s_.baseline_kpa[fs] = s_.window_sum_kpa[fs] / s_.window_cycles;  // the tare
  }
  s_.armed = 1;
  s_.window_cycles = 0;
}

bool ContactDetector::step_rt(const ContactInputs& in, ContactState& out, ContactEvent& event) noexcept {
  const bool healthy = hand_healthy_rt(in) && tactile_healthy(in);
  out.timestamp_ns = in.time_ns;
  out.threshold_rad = static_cast<float>(s_.armed != 0 ? s_.enter_rad : c_.enter_rad);
  out.healthy = healthy ? 1 : 0;
  auto publish = [&] {
    out.armed = s_.armed;
    out.in_contact = s_.in_contact;
    out.fingers = s_.fingers;
    out.source = s_.source;
    out.since_ns = s_.in_contact != 0 ? s_.since_ns : 0;
    out.onsets = s_.onsets;
  };
  if (!healthy) {  // frozen: no decision on stale data
    if (s_.in_contact == 0) {
      s_.armed = 0;
      s_.window_cycles = 0;
    }
    s_.debounce = s_.joint_run = 0;
    s_.tactile_run.fill(0);
    publish();
    return false;
  }

  std::array<double, kFingers> kpa{};
  std::uint8_t kpa_valid = 0;
  pressures(in, kpa, kpa_valid);
  const HandState& h = *in.hand;

  if (s_.armed != 0 && s_.in_contact == 0 && in.command != nullptr) {
    for (int j = 0; j < kJoints; ++j) {
      const auto js = static_cast<std::size_t>(j);
      if (c_.weight[js] > 0 && std::fabs(in.command->target_rad[j] - s_.target_ref[js]) > c_.rearm_rad) {
        s_.armed = 0;  // a new posture: settle again for its relaxed pose
        s_.window_cycles = 0;
        break;
      }
    }
  }
  if (s_.armed == 0) {
    s_.joint_run = 0;
    s_.tactile_run.fill(0);
    settle_rt(in, kpa);
    out.deviation_rad = 0;
    for (float& d : out.finger_deviation_rad) d = 0;
    publish();
    return false;
  }

  // Eq. 5: the P-weighted deviation from the relaxed pose (commanded moves taken out).
  double total2 = 0;
  std::array<double, kFingers> finger2{};
  for (int j = 0; j < kJoints; ++j) {
    const auto js = static_cast<std::size_t>(j);
    const double w = c_.weight[js];
    if (w <= 0) continue;
    double d = h.position_rad[j] - s_.theta_ref[js];
    if (in.command != nullptr) d -= in.command->target_rad[j] - s_.target_ref[js];
    total2 += w * d * d;
    const int f = robot::finger_of_hand_joint(j);
    if (f >= 0) finger2[static_cast<std::size_t>(f)] += w * d * d;
  }
  const double total = std::sqrt(total2);
  out.deviation_rad = static_cast<float>(total);
  int most = -1;
  for (int f = 0; f < kFingers; ++f) {
    const auto fs = static_cast<std::size_t>(f);
    out.finger_deviation_rad[f] = static_cast<float>(std::sqrt(finger2[fs]));
    if (finger2[fs] > 0 && (most < 0 || finger2[fs] > finger2[static_cast<std::size_t>(most)])) most = f;
  }

  const bool in_contact = s_.in_contact != 0;
  const bool joint_raw = total > (in_contact ? s_.exit_rad : s_.enter_rad);
  std::uint8_t fingers = 0;
  std::uint8_t source = joint_raw ? contact_joints : contact_none;
  if (joint_raw) {
    for (int f = 0; f < kFingers; ++f)
      if (out.finger_deviation_rad[f] > 0.5 * s_.enter_rad) fingers |= static_cast<std::uint8_t>(1u << f);
    if (fingers == 0 && most >= 0) fingers = static_cast<std::uint8_t>(1u << most);
  }
  const double tac_threshold = in_contact ? c_.tactile_exit_kpa : c_.tactile_enter_kpa;
  std::uint8_t tac_fingers = 0;
  for (int f = 0; f < kFingers && c_.tactile != TactileSource::none; ++f) {
    const auto fs = static_cast<std::size_t>(f);
    const bool over = (kpa_valid & (1u << f)) != 0 && kpa[fs] - s_.baseline_kpa[fs] > tac_threshold;
    s_.tactile_run[fs] = over ? s_.tactile_run[fs] + 1 : 0;
    if (over) tac_fingers |= static_cast<std::uint8_t>(1u << f);
  }
  if (joint_raw) {
    s_.spike_rad = std::max(s_.spike_rad, total);
  } else if (s_.joint_run > 0 && !in_contact && c_.spike_margin > 0) {  // a spike the debounce rejected
    ++s_.spikes;
    const double enter = std::max(s_.enter_rad, c_.spike_margin * s_.spike_rad);
    s_.exit_rad *= enter / s_.enter_rad;
    s_.enter_rad = enter;
  }
  if (!joint_raw) s_.spike_rad = 0;
  s_.joint_run = joint_raw ? s_.joint_run + 1 : 0;
  if (tac_fingers != 0) {
    fingers |= tac_fingers;
    source |= contact_tactile;
  }
  const bool raw = source != contact_none;

  // Debounce, per source and per fingertip (so that noise on two sensors in turn does not add
  // up): an onset needs one test to hold for debounce_cycles in a row, a release every test to
  // stay quiet that long.
  bool changed = false;
  if (!in_contact) {
    bool onset = s_.joint_run >= c_.debounce_cycles;
    for (int f = 0; f < kFingers; ++f) onset = onset || s_.tactile_run[static_cast<std::size_t>(f)] >= c_.debounce_cycles;
    if (onset) {
      s_.in_contact = 1;
      s_.since_ns = in.time_ns;
      ++s_.onsets;
      changed = true;
    }
    s_.debounce = 0;
  } else if (!raw) {
    if (++s_.debounce >= c_.debounce_cycles) {
      s_.in_contact = 0;
      s_.debounce = 0;
      changed = true;
    }
  } else {
    s_.debounce = 0;
  }
  if (s_.in_contact != 0) {
    if (fingers != 0) s_.fingers = fingers;  // never empty while in contact
    if (source != contact_none) s_.source = source;
  } else {
    s_.fingers = 0;
    s_.source = contact_none;
    if (!raw) {  // follow the drift of untouched sensors
      const double a = std::min(1.0, in.dt_s / c_.baseline_time_constant_s);
      for (int f = 0; f < kFingers; ++f) {
        const auto fs = static_cast<std::size_t>(f);
        s_.baseline_kpa[fs] += a * (kpa[fs] - s_.baseline_kpa[fs]);
      }
    }
  }
  publish();
  if (changed) {
    event.timestamp_ns = in.time_ns;
    event.onset = s_.in_contact;
    event.fingers = s_.in_contact != 0 ? s_.fingers : 0;
    event.source = s_.in_contact != 0 ? s_.source : static_cast<std::uint8_t>(contact_none);
  }
  return changed;
}

}  // namespace crease::contact
