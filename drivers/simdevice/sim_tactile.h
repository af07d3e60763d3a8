// SimTactile: the device side of the tactile protocol (drivers/README.md §6) on a byte fd (a
// pty master). After Start it streams samples at the requested rate; each fingertip's taxels
// follow the contact force set with set_contact_force (a fixed bell-shaped footprint, 10 kPa
// per N at the centre taxel), or, with external_pressures, the taxel pressures a simulated
// world computed (set_pressures: plugins/sim_world/tactile_model.h). step() is non-blocking.
#pragma once

#include <atomic>

#include "drivers/protocol/tactile_protocol.h"
#include "drivers/serial/serial_port.h"

namespace crease::drivers::sim {

class SimTactile {
 public:
  explicit SimTactile(int fd, bool external_pressures = false) noexcept : link_(fd), external_(external_pressures) {}
  void step(std::int64_t now_ns) noexcept;
  void set_contact_force(int fingertip, float force_n) noexcept { force_[fingertip].store(force_n); }
  // external_pressures: what the next samples carry (kPa), from the thread that calls step().
  void set_pressures(const float (&kpa)[tactile::kFingertips][tactile::kTaxels]) noexcept;
  void set_silent(bool s) noexcept { silent_.store(s); }
  // From the thread that calls step(): serve a new link (another connection of a socket
  // link) from scratch, silent until its Start. RT-safe.
  void reset_link(int fd) noexcept;
  [[nodiscard]] std::uint64_t samples_sent() const noexcept { return sent_.load(); }
  // Samples the link did not take whole (its buffer full: the reader behind), dropped.
  [[nodiscard]] std::uint64_t samples_dropped() const noexcept { return dropped_.load(); }
  [[nodiscard]] std::uint16_t rate_hz() const noexcept { return rate_pub_.load(); }

 private:
  SerialLink link_;
  std::uint16_t rate_hz_ = 0;
  std::uint16_t counter_ = 0;
  std::int64_t next_ns_ = 0, t0_ns_ = 0;
  std::atomic<std::uint64_t> sent_{0}, dropped_{0};
  std::atomic<std::uint16_t> rate_pub_{0};
  std::atomic<float> force_[tactile::kFingertips] = {};
  std::atomic<bool> silent_{false};
  const bool external_;
  float pressure_kpa_[tactile::kFingertips][tactile::kTaxels] = {};
};

}  // namespace crease::drivers::sim
