// CanDeviceHost: what the controller side of every CANopen-style device on its own CAN FD bus
// shares (drivers/README.md §2, §8); HandHost and ArmHost derive from it and add their PDOs.
//   read:  drain the bus (at most 256 frames), let the device decode its PDOs, handle EMCY and
//          heartbeats, feed the LinkMonitor, track whether the device is operational.
//   write: bus-off -> restart at once, then every restart_period_cycles, sending nothing; otherwise one batch
//          of [NMT start while not operational, every nmt_retry_cycles] + the device's frames +
//          SYNC (next counter) + [host heartbeat every heartbeat_period_cycles].
// Every call is RT-safe for a MockCanBus (SocketCanBus::restart uses netlink).
#pragma once

#include <cstddef>
#include <cstdint>

#include "drivers/can/can_bus.h"
#include "drivers/host/link_monitor.h"
#include "drivers/protocol/canopen.h"
#include "drivers/protocol/decode_result.h"

namespace crease::drivers {

class CanDeviceHost {
 public:
  [[nodiscard]] const LinkMonitor& monitor() const noexcept { return monitor_; }
  // SYNC counter sent by the last write (a fresh status answers exactly this one).
  [[nodiscard]] std::uint8_t last_sync_sent() const noexcept { return sync_; }
  // True when the last write commanded the safe state (or could send nothing: bus-off).
  [[nodiscard]] bool commanding_safe_state() const noexcept { return safe_sent_; }
  [[nodiscard]] std::uint16_t last_sent_seq() const noexcept { return seq_; }
  [[nodiscard]] std::uint64_t send_failures() const noexcept { return send_failures_; }
  // EMCY 0x8130 received: the device held itself safe because our commands stopped reaching it.
  [[nodiscard]] std::uint64_t host_timeout_emcys() const noexcept { return host_timeout_emcys_; }

 protected:
  static constexpr std::size_t kMaxBatch = 6;

  CanDeviceHost(CanBus& bus, std::uint8_t node, const LinkMonitorConfig& monitor, int heartbeat_period_cycles,
                int nmt_retry_cycles, int restart_period_cycles) noexcept
      : bus_(bus), monitor_(monitor), node_(node), heartbeat_period_cycles_(heartbeat_period_cycles),
        nmt_retry_cycles_(nmt_retry_cycles), restart_period_cycles_(restart_period_cycles) {}

  // Read phase. on_frame(const RxFrame&) -> bool decodes the device's PDOs (true = consumed,
  // typically through take()); EMCY and heartbeats of this node are handled here.
  template <typename OnFrame>
  void read_bus(OnFrame&& on_frame) noexcept {
    monitor_.begin_read();
    RxFrame rx;
    for (int i = 0; i < 256; ++i) {
      const RecvResult r = bus_.try_receive(rx);
      if (r == RecvResult::empty || r == RecvResult::error) break;
      if (r != RecvResult::frame) continue;
      if (!on_frame(static_cast<const RxFrame&>(rx))) on_service_frame(rx.frame);
    }
    monitor_.end_read(bus_.state() == BusState::bus_off);
  }

  // Decodes msg from f with the protocol's decode(node, frame, msg). ok -> on_ok(msg);
  // bad_crc -> counted by the monitor. Returns false when the frame is not this message.
  template <typename Msg, typename OnOk>
  bool take(const CanFrame& f, Msg& msg, OnOk&& on_ok) noexcept {
    const Decode d = decode(node_, f, msg);
    if (d == Decode::ok) {
      on_ok(static_cast<const Msg&>(msg));
      return true;
    }
    if (d == Decode::bad_crc) {
      monitor_.on_bad_crc();
      return true;
    }
    return false;
  }

  // A decoded status (fields nmt, cmd_seq, sync_counter, device_time_us): records the NMT
  // state; true when the status is fresh.
  template <typename Status>
  bool accept_status(const Status& st) noexcept {
    operational_ = st.nmt == canopen::NmtState::operational;
    return monitor_.on_status(st.cmd_seq, st.sync_counter, st.device_time_us);
  }

  // Write phase: begin_write() returns false on bus-off (nothing can be sent; the device's own
  // watchdog holds it safe); otherwise the caller numbers its command with next_seq(), add()s
  // its frames and calls end_write() with that seq.
  bool begin_write() noexcept;
  std::uint16_t next_seq() noexcept { return ++seq_; }
  void add(const CanFrame& f) noexcept { batch_[batch_len_++] = f; }
  void end_write(std::uint16_t seq) noexcept;
  [[nodiscard]] std::uint64_t cycle() const noexcept { return cycle_; }

  CanBus& bus_;
  LinkMonitor monitor_;
  std::uint8_t node_;
  bool safe_sent_ = false;

 private:
  void on_service_frame(const CanFrame& f) noexcept;

  int heartbeat_period_cycles_, nmt_retry_cycles_, restart_period_cycles_;
  std::uint16_t seq_ = 0;
  std::uint64_t bus_off_cycles_ = 0;  // write cycles in a row that found the bus off
  std::uint8_t sync_ = 0;
  bool operational_ = false;
  std::uint64_t cycle_ = 0, send_failures_ = 0, host_timeout_emcys_ = 0;
  CanFrame batch_[kMaxBatch];
  std::size_t batch_len_ = 0;
};

}  // namespace crease::drivers
