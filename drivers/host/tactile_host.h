// TactileHost: the controller side of the tactile matrix on a serial link (drivers/README.md
// §6). It sends Start (and repeats it while no sample arrives), keeps the newest sample and
// reports its age; stale beyond max_age_ns means fault. No allocation, but read_from_rt reads
// and writes the tty where it is called, and a tty's non-blocking read can stay in the kernel
// for milliseconds: a loop's update reads through TactileReader (tactile_reader.h) instead,
// whose thread does the I/O. Tests and tools that own their timing use this directly.
#pragma once

#include "drivers/host/link_monitor.h"
#include "drivers/protocol/tactile_protocol.h"
#include "drivers/serial/serial_port.h"

namespace crease::drivers {

struct TactileHostConfig {
  std::uint16_t rate_hz = 250;
  std::int64_t max_age_ns = 20'000'000;  // older than this: fault
  std::int64_t start_retry_ns = 100'000'000;
  // TactileReader's thread: SCHED_FIFO at this priority where the process may (0: it keeps
  // the policy it inherits). Its work per wake-up is bounded (one read, deframing), so it may
  // preempt every non-real-time thread without starving them; below the loops.
  int thread_priority = 1;
};

// The health of a tactile link (TactileHost's and TactileReader's): no sample yet, or the
// newest received more than max_age_ns before now: fault; framing errors (CRC or COBS) seen and
// no sample for two sample periods: degraded; else ok. RT-safe.
[[nodiscard]] LinkHealth tactile_health(const TactileHostConfig& cfg, std::uint64_t samples, std::int64_t rx_ns,
                                        std::uint64_t framing_errors, std::int64_t now_ns) noexcept;

class TactileHost {
 public:
  TactileHost(int fd, const TactileHostConfig& cfg) noexcept : link_(fd), cfg_(cfg) {}
  // Reads everything waiting; returns true if a new sample arrived this call.
  bool read_from_rt(std::int64_t now_ns) noexcept;
  [[nodiscard]] const tactile::Sample& sample() const noexcept { return sample_; }
  [[nodiscard]] std::int64_t sample_rx_ns() const noexcept { return rx_ns_; }
  [[nodiscard]] LinkHealth health(std::int64_t now_ns) const noexcept;
  [[nodiscard]] const SerialLink& link() const noexcept { return link_; }
  [[nodiscard]] std::uint64_t samples() const noexcept { return samples_; }

 private:
  SerialLink link_;
  TactileHostConfig cfg_;
  tactile::Sample sample_;
  std::int64_t rx_ns_ = 0, last_start_ns_ = 0;
  std::uint64_t samples_ = 0;
  bool started_ = false;
};

}  // namespace crease::drivers
