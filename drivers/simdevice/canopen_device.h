// CanopenDevice: the device-side CANopen services every simulated CAN device shares
// (drivers/README.md §2): boot-up heartbeat, NMT (start / stop / pre-operational / reset node,
// each answered with a heartbeat), SYNC (in operational: advance the dynamics and send the
// status), the periodic heartbeat, EMCY, the command watchdog clock, bus-off auto restart and
// the "silent" failure mode. SimHand and SimArm derive from it and add their PDOs and dynamics.
// step() is non-blocking and RT-safe: call it whenever the bus fd is readable and at least
// every 1 ms, from one thread.
#pragma once

#include <atomic>
#include <cstdint>

#include "drivers/can/can_bus.h"
#include "drivers/protocol/canopen.h"
#include "drivers/protocol/decode_result.h"

namespace crease::drivers::sim {

// Written by the device's thread, readable from any thread.
struct SimDeviceCounters {
  std::atomic<std::uint64_t> commands{0}, bad_crc{0}, syncs{0}, statuses_sent{0}, send_failures{0};
  std::atomic<std::uint64_t> watchdog_trips{0}, emcy_sent{0};
};

class CanopenDevice {
 public:
  CanopenDevice(const CanopenDevice&) = delete;
  CanopenDevice& operator=(const CanopenDevice&) = delete;
  // Processes received frames and advances the dynamics to now_ns.
  void step(std::int64_t now_ns) noexcept;
  // A device that stops answering (but keeps its state), for failure tests.
  void set_silent(bool s) noexcept { silent_.store(s); }
  [[nodiscard]] const SimDeviceCounters& counters() const noexcept { return counters_; }

  // The command watchdog's bound (ns of the device's clock).
  [[nodiscard]] std::int64_t watchdog_ns() const noexcept { return watchdog_ns_; }

 protected:
  CanopenDevice(CanBus& bus, std::uint8_t node, std::int64_t watchdog_ns, std::int64_t heartbeat_period_ns,
                bool auto_start) noexcept
      : bus_(bus), node_(node), watchdog_ns_(watchdog_ns), heartbeat_period_ns_(heartbeat_period_ns),
        auto_start_(auto_start) {}
  ~CanopenDevice() = default;

  // The device's own frames (everything but NMT and SYNC).
  virtual void on_pdo(const CanFrame& f, std::int64_t now_ns) noexcept = 0;
  // Advances the dynamics to now_ns (uses and updates last_step_ns_).
  virtual void integrate(std::int64_t now_ns) noexcept = 0;
  // Answers a SYNC in operational (after integrate).
  virtual void send_status() noexcept = 0;
  // Between reading the bus and the heartbeat: fault and watchdog handling, then integrate.
  virtual void supervise(std::int64_t now_ns) noexcept = 0;
  // End of step(): publish observers.
  virtual void publish() noexcept = 0;

  // A decoded command with result d: bad CRCs are counted; an ok command in operational is
  // counted, the dynamics advanced to now_ns, its seq becomes the echoed one and the watchdog
  // restarts. True when the caller should apply it.
  bool accept_command(Decode d, std::uint16_t seq, std::int64_t now_ns) noexcept;
  // Sends unless silent; failures counted.
  void send(const CanFrame& f) noexcept;
  // EMCY with the given code (error register 0x01 unless code is the error reset).
  void emcy(std::uint16_t code, std::int64_t now_ns) noexcept;
  [[nodiscard]] bool command_timed_out(std::int64_t now_ns) const noexcept { return now_ns - last_cmd_ns_ > watchdog_ns_; }
  [[nodiscard]] std::uint32_t device_time_us() const noexcept { return static_cast<std::uint32_t>((last_step_ns_ - t0_ns_) / 1000); }

  CanBus& bus_;
  const std::uint8_t node_;
  canopen::NmtState nmt_ = canopen::NmtState::boot_up;
  std::uint16_t cmd_seq_ = 0;       // seq of the last command applied
  std::uint8_t sync_counter_ = 0;   // counter of the last SYNC
  std::int64_t last_step_ns_ = 0;
  SimDeviceCounters counters_;

 private:
  void on_frame(const CanFrame& f, std::int64_t now_ns) noexcept;

  const std::int64_t watchdog_ns_, heartbeat_period_ns_;
  const bool auto_start_;
  bool booted_ = false;
  std::int64_t last_cmd_ns_ = 0, last_heartbeat_ns_ = 0, t0_ns_ = 0;
  std::atomic<bool> silent_{false};
};

}  // namespace crease::drivers::sim
