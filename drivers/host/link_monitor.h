// LinkMonitor: the host's bookkeeping for one device on a cyclic link (drivers/README.md §2):
// which command seqs were acknowledged or failed, whether this cycle's status is fresh, how
// many cycles the device has been silent, bad-CRC frames in a sliding window, bus-off and
// emergencies -> a health value. Pure logic, RT-safe, no I/O (HandHost / ArmHost feed it).
#pragma once

#include <cstdint>

namespace crease::drivers {

enum class LinkHealth : std::uint8_t {
  ok,        // fresh data every cycle
  degraded,  // a cycle without fresh data, or a recent CRC error: data may be one cycle old
  fault,     // silent >= timeout_cycles, bus-off, CRC errors above threshold or an emergency:
             // the host commands the safe state
};
[[nodiscard]] const char* to_string(LinkHealth h) noexcept;

struct LinkMonitorConfig {
  int timeout_cycles = 2;         // cycles without a fresh status before fault
  int crc_window_cycles = 100;
  int crc_threshold = 10;         // bad-CRC frames within the window before fault
  // Start-up: cycles the device has to answer a first time before its silence counts as a
  // device fault (a link that never answered is `fault` but not yet reported as gone).
  int first_contact_cycles = 1000;
  // Consecutive cycles in `fault` before the driver reports the device as gone
  // (Status::device_fault, device_port_glue.h): shorter gaps command the safe state all the
  // same but are no device fault (a loaded machine's late answers are not a lost device).
  int device_fault_cycles = 50;
  // A bus-off the host restarts at once (can_device_host.h) is `degraded`, not `fault`, for its
  // first bus_off_grace_cycles cycles, the device's silence then included: the data is a few
  // cycles old, as after lost frames, and a consumer's own staleness bound decides. A bus-off
  // still off, or a device still silent, after that is a fault as before. 0: a fault at once.
  int bus_off_grace_cycles = 3;
};

struct LinkCounters {
  std::uint64_t commands_sent = 0, commands_acked = 0, commands_failed = 0;
  std::uint64_t fresh = 0, stale = 0, bad_crc = 0, timeouts = 0, emergencies = 0, recoveries = 0;
  std::uint64_t bus_offs = 0, bus_offs_ridden = 0;  // bus-offs seen; of them, over within the grace
};

class LinkMonitor {
 public:
  explicit LinkMonitor(const LinkMonitorConfig& cfg = {}) noexcept : cfg_(cfg) {}

  // Start of a cycle's read phase.
  void begin_read() noexcept;
  // A decoded status: the seq it echoes, the SYNC counter it answers and the device time.
  // Returns true when the status is fresh (answers the last SYNC we sent, time advanced).
  bool on_status(std::uint16_t cmd_seq, std::uint8_t sync_counter, std::uint32_t device_time_us) noexcept;
  void on_bad_crc() noexcept;
  void on_emergency(bool active) noexcept;  // active = error code != 0
  // End of the read phase: updates silence, the CRC window and the health.
  void end_read(bool bus_off) noexcept;
  // Write phase: the seq and SYNC counter this cycle sent.
  void on_sent(std::uint16_t seq, std::uint8_t sync_counter) noexcept;

  [[nodiscard]] LinkHealth health() const noexcept { return health_; }
  [[nodiscard]] bool fresh_this_cycle() const noexcept { return fresh_this_cycle_; }
  [[nodiscard]] int silent_cycles() const noexcept { return silent_cycles_; }
  [[nodiscard]] bool emergency_active() const noexcept { return emergency_; }
  // The device has answered once, or first_contact_cycles passed without an answer: from here
  // on a `fault` health is the device's fault (silent past the timeout, bus-off, CRC errors, an
  // emergency), reported to the host as Status::device_fault (device_port_glue.h).
  [[nodiscard]] bool past_start_up() const noexcept {
    return ever_fresh_ || cycle_ >= static_cast<std::uint64_t>(cfg_.first_contact_cycles);
  }
  [[nodiscard]] std::uint16_t last_acked_seq() const noexcept { return last_acked_; }
  [[nodiscard]] const LinkCounters& counters() const noexcept { return counters_; }
  // Seq of the newest command still waiting for its acknowledgement (valid if pending()).
  [[nodiscard]] bool pending() const noexcept { return pending_count_ > 0; }

 private:
  LinkMonitorConfig cfg_;
  LinkHealth health_ = LinkHealth::fault;  // until the device has answered once
  bool fresh_this_cycle_ = false;
  bool emergency_ = false;
  bool ever_fresh_ = false;
  int silent_cycles_ = 0;
  int bus_off_age_ = -1;  // cycles since the current bus-off began, until a fresh status; -1: none
  bool bus_off_faulted_ = false;  // the current bus-off outlived its grace
  std::uint16_t last_acked_ = 0;
  std::uint8_t last_sync_sent_ = 0;
  std::uint32_t last_device_time_ = 0;
  // Commands awaiting acknowledgement: seq and the cycle they were sent (ring of 4).
  std::uint16_t pending_seq_[4] = {};
  std::uint64_t pending_cycle_[4] = {};
  int pending_count_ = 0;
  std::uint64_t cycle_ = 0;
  // Bad CRCs per cycle over the window (ring).
  std::uint16_t crc_ring_[256] = {};
  int crc_in_window_ = 0;
  std::uint16_t crc_this_cycle_ = 0;
  LinkCounters counters_;
};

}  // namespace crease::drivers
