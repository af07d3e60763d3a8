#include "drivers/simdevice/sim_tactile.h"

#include <cmath>

namespace crease::drivers::sim {

void SimTactile::set_pressures(const float (&kpa)[tactile::kFingertips][tactile::kTaxels]) noexcept {
  for (int ft = 0; ft < tactile::kFingertips; ++ft)
    for (int t = 0; t < tactile::kTaxels; ++t) pressure_kpa_[ft][t] = kpa[ft][t];
}

void SimTactile::step(std::int64_t now_ns) noexcept {
  if (t0_ns_ == 0) t0_ns_ = now_ns;
  SerialFrame f;
  while (link_.poll_from_rt(f)) {
    std::uint16_t rate = 0;
    if (tactile::decode_start(f, rate) == Decode::ok) {
      rate_hz_ = rate;
      rate_pub_.store(rate);
      next_ns_ = now_ns;
    } else if (f.type == tactile::kTypeStop) {
      rate_hz_ = 0;
      rate_pub_.store(0);
    }
  }
  if (rate_hz_ == 0 || now_ns < next_ns_ || silent_.load(std::memory_order_relaxed)) return;
  next_ns_ += 1'000'000'000 / rate_hz_;
  if (next_ns_ < now_ns) next_ns_ = now_ns;  // fell behind: skip, never burst
  tactile::Sample s;
  s.device_time_us = static_cast<std::uint32_t>((now_ns - t0_ns_) / 1000);
  s.sample_counter = counter_++;
  s.valid = 0x1F;
  for (int ft = 0; ft < tactile::kFingertips && external_; ++ft)
    for (int t = 0; t < tactile::kTaxels; ++t) s.pressure_kpa[ft][t] = pressure_kpa_[ft][t];
  for (int ft = 0; ft < tactile::kFingertips && !external_; ++ft) {
    const float force = force_[ft].load(std::memory_order_relaxed);
    for (int t = 0; t < tactile::kTaxels; ++t) {
      const float d = (static_cast<float>(t) - 16.5f) / 8.0f;
      s.pressure_kpa[ft][t] = force > 0 ? 10.0f * force * std::exp(-d * d) : 0.0f;
    }
  }
  std::uint8_t payload[tactile::kSampleLen];
  const std::size_t n = tactile::encode_sample(s, payload);
  if (link_.send_from_rt(tactile::kTypeSample, {payload, n})) {
    ++sent_;
  } else {
    ++dropped_;
  }
}

void SimTactile::reset_link(int fd) noexcept {
  link_ = SerialLink(fd);
  rate_hz_ = 0;
  rate_pub_.store(0);
}

}  // namespace crease::drivers::sim
