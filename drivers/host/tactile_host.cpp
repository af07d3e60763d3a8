#include "drivers/host/tactile_host.h"

namespace crease::drivers {

bool TactileHost::read_from_rt(std::int64_t now_ns) noexcept {
  bool got = false;
  SerialFrame f;
  while (link_.poll_from_rt(f)) {
    tactile::Sample s;
    if (tactile::decode_sample(f, s) == Decode::ok) {
      sample_ = s;
      rx_ns_ = now_ns;
      ++samples_;
      got = true;
    }
  }
  const bool stale = samples_ == 0 || now_ns - rx_ns_ > cfg_.max_age_ns;
  if (stale && (!started_ || now_ns - last_start_ns_ >= cfg_.start_retry_ns)) {
    std::uint8_t p[2];
    const std::size_t n = tactile::encode_start(cfg_.rate_hz, p);
    started_ = link_.send_from_rt(tactile::kTypeStart, {p, n}) || started_;
    last_start_ns_ = now_ns;
  }
  return got;
}

LinkHealth tactile_health(const TactileHostConfig& cfg, std::uint64_t samples, std::int64_t rx_ns,
                          std::uint64_t framing_errors, std::int64_t now_ns) noexcept {
  if (samples == 0 || now_ns - rx_ns > cfg.max_age_ns) return LinkHealth::fault;
  if (framing_errors > 0 && now_ns - rx_ns > 2 * 1'000'000'000 / (cfg.rate_hz ? cfg.rate_hz : 1)) {
    return LinkHealth::degraded;
  }
  return LinkHealth::ok;
}

LinkHealth TactileHost::health(std::int64_t now_ns) const noexcept {
  return tactile_health(cfg_, samples_, rx_ns_, link_.rx_stats().crc_errors + link_.rx_stats().cobs_errors, now_ns);
}

}  // namespace crease::drivers
