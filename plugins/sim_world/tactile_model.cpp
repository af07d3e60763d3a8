#include "plugins/sim_world/tactile_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace crease::world {

TactileModel::Layout TactileModel::layout(double pitch_mm) noexcept {
  Layout l{};
  int k = 0;
  for (int row = 0; row < 6; ++row) {    // along the finger, proximal to distal
    for (int col = 0; col < 6; ++col) {  // across
      if (row == 5 && (col == 0 || col == 5)) continue;  // the rounded distal corners
      l[static_cast<std::size_t>(k++)] = {(row - 2.5) * pitch_mm, (col - 2.5) * pitch_mm};
    }
  }
  return l;
}

TactileModel::TactileModel(const robot::TactileParams& p, std::uint64_t seed)
    : p_(p), layout_(layout(p.taxel.pitch_mm)), rng_(seed ^ 0x7AC711E5EED5ull) {}

double TactileModel::gaussian() noexcept {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u1 = 0;
  do {
    u1 = static_cast<double>(rng_.next() >> 11) * 0x1.0p-53;
  } while (u1 <= 0.0);
  const double u2 = static_cast<double>(rng_.next() >> 11) * 0x1.0p-53;
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * std::numbers::pi * u2);
}

void TactileModel::taxels_rt(double normal_force_n, double x_mm, double y_mm, float out_kpa[kTaxels]) noexcept {
  const auto& t = p_.taxel;
  const double s2 = t.contact_sigma_mm * t.contact_sigma_mm;
  // Peak pressure of the Gaussian carrying F: F / (2 pi sigma^2) N/mm^2 = 1000 x that kPa.
  const double peak_kpa = 1000.0 * std::max(0.0, normal_force_n) / (2.0 * std::numbers::pi * s2);
  const double lsb = t.range_kpa / static_cast<double>((1 << t.adc_bits) - 1);
  for (int k = 0; k < kTaxels; ++k) {
    const double dx = layout_[static_cast<std::size_t>(k)][0] - x_mm;
    const double dy = layout_[static_cast<std::size_t>(k)][1] - y_mm;
    double p = peak_kpa * std::exp(-(dx * dx + dy * dy) / (2.0 * s2)) + t.noise_kpa * gaussian();
    if (p < t.threshold_kpa) p = 0.0;
    p = std::min(p, t.range_kpa);
    out_kpa[k] = static_cast<float>(std::round(p / lsb) * lsb);
  }
}

void TactileModel::taxels_rt(const WorldHand& hand, float out_kpa[kFingertips][kTaxels]) noexcept {
  for (int f = 0; f < kFingertips; ++f) {
    const WorldFingertip& tip = hand.tip[f];
    taxels_rt(tip.contact != 0 ? tip.normal_force_n : 0.0, 0.0, 0.0, out_kpa[f]);
  }
}

double TactileModel::taxel_force_n(const float kpa[kTaxels]) const noexcept {
  double sum = 0;
  for (int k = 0; k < kTaxels; ++k) sum += kpa[k];
  return sum * p_.taxel.taxel_area_mm2 / 1000.0;
}

float TactileModel::pst_rt(int tip, double normal_force_n, double dt_s) noexcept {
  const auto& s = p_.pst;
  const auto f = static_cast<std::size_t>(tip);
  pst_drift_kpa_[f] += s.drift_kpa_per_s * dt_s;
  const double raw = s.kpa_per_n * std::max(0.0, normal_force_n) + pst_drift_kpa_[f];
  // First-order high-pass: the electronics subtract a low-passed copy of the input.
  pst_baseline_kpa_[f] += (raw - pst_baseline_kpa_[f]) * std::min(1.0, dt_s / s.highpass_time_constant_s);
  double p = raw - pst_baseline_kpa_[f] + s.noise_kpa * gaussian();
  p = std::clamp(p, 0.0, s.range_kpa);
  return static_cast<float>(std::round(p * 100.0) / 100.0);  // the wire's 0.01 kPa
}

void TactileModel::pst_rt(const WorldHand& hand, double dt_s, float out_kpa[kFingertips]) noexcept {
  for (int f = 0; f < kFingertips; ++f) {
    const WorldFingertip& tip = hand.tip[f];
    out_kpa[f] = pst_rt(f, tip.contact != 0 ? tip.normal_force_n : 0.0, dt_s);
  }
}

}  // namespace crease::world
