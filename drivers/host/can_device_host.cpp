#include "drivers/host/can_device_host.h"

namespace crease::drivers {

void CanDeviceHost::on_service_frame(const CanFrame& f) noexcept {
  canopen::Emcy e;
  if (canopen::decode_emcy(f, e) && e.node == node_) {
    // A host-timeout EMCY reports that the device already holds itself safe (our commands
    // stopped reaching it); it clears when our commands arrive again, so it does not latch.
    if (e.code == canopen::kEmcyHostTimeout) ++host_timeout_emcys_;
    monitor_.on_emergency(e.code != canopen::kEmcyReset && e.code != canopen::kEmcyHostTimeout);
    return;
  }
  std::uint8_t node;
  canopen::NmtState s;
  if (canopen::decode_heartbeat(f, node, s) && node == node_) operational_ = s == canopen::NmtState::operational;
}

bool CanDeviceHost::begin_write() noexcept {
  ++cycle_;
  batch_len_ = 0;
  if (bus_.state() == BusState::bus_off) {
    // The first cycle that finds the bus off restarts it (as SocketCAN's restart-ms does after
    // its delay), then every restart_period_cycles while it stays off.
    if (bus_off_cycles_ % static_cast<std::uint64_t>(restart_period_cycles_) == 0) bus_.restart();
    ++bus_off_cycles_;
    safe_sent_ = true;
    return false;
  }
  bus_off_cycles_ = 0;
  if (!operational_ && cycle_ % static_cast<std::uint64_t>(nmt_retry_cycles_) == 1) {
    add(canopen::encode_nmt(canopen::NmtCommand::start, node_));
  }
  return true;
}

void CanDeviceHost::end_write(std::uint16_t seq) noexcept {
  sync_ = canopen::next_sync_counter(sync_);
  add(canopen::encode_sync(sync_));
  monitor_.on_sent(seq, sync_);
  if (cycle_ % static_cast<std::uint64_t>(heartbeat_period_cycles_) == 1) {
    add(canopen::encode_heartbeat(canopen::kHostNode, canopen::NmtState::operational));
  }
  // Everything this cycle sends goes out in one batch (one sendmmsg on SocketCAN, one ring
  // update on the mock bus).
  SendResult last;
  send_failures_ += batch_len_ - bus_.send_batch({batch_, batch_len_}, &last);
}

}  // namespace crease::drivers
