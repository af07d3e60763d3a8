#include "drivers/host/hand_host.h"

#include <cstring>

namespace crease::drivers {

HandHost::HandHost(CanBus& bus, const HandHostConfig& cfg) noexcept
    : CanDeviceHost(bus, cfg.node, cfg.monitor, cfg.heartbeat_period_cycles, cfg.nmt_retry_cycles,
                    cfg.restart_period_cycles),
      cfg_(cfg) {}

void HandHost::read_from_rt(std::int64_t now_ns) noexcept {
  (void)now_ns;
  reading_.fresh = false;
  reading_.pressure_fresh = false;
  read_bus([this](const RxFrame& rx) {
    hand::Status st;
    if (take(rx.frame, st, [&](const hand::Status& s) {
          if (!accept_status(s)) return;
          reading_.status = s;
          reading_.status_rx_ns = rx.timestamp_ns;
          reading_.fresh = true;
        })) {
      return true;
    }
    hand::Pressure p;
    return take(rx.frame, p, [&](const hand::Pressure& q) {
      if (q.sync_counter != last_sync_sent()) return;
      reading_.pressure = q;
      reading_.pressure_fresh = true;
    });
  });
}

void HandHost::write_from_rt(const hand::Command& desired, const hand::Stiffness& stiffness, std::int64_t now_ns) noexcept {
  (void)now_ns;
  if (!begin_write()) return;
  hand::Command c = desired;
  c.seq = next_seq();
  safe_sent_ = monitor_.health() == LinkHealth::fault;
  if (safe_sent_) {
    c.flags = 0;  // hold position, zero force
    for (int j = 0; j < hand::kJoints; ++j) c.target_rad[j] = reading_.status.position_rad[j];
  }
  add(hand::encode(cfg_.node, c));
  const bool changed = !stiffness_sent_ ||
                       std::memcmp(last_stiffness_, stiffness.stiffness_nm_per_rad, sizeof(last_stiffness_)) != 0;
  if (changed || cycle() - last_stiff_cycle_ >= 100) {
    hand::Stiffness s = stiffness;
    s.seq = ++stiff_seq_;
    add(hand::encode(cfg_.node, s));
    std::memcpy(last_stiffness_, stiffness.stiffness_nm_per_rad, sizeof(last_stiffness_));
    last_stiff_cycle_ = cycle();
    stiffness_sent_ = true;
  }
  end_write(c.seq);
}

}  // namespace crease::drivers
