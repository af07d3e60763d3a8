#include "drivers/can/can_bus.h"

#include <linux/can/error.h>

namespace crease::drivers {

const char* to_string(BusState s) noexcept {
  switch (s) {
    case BusState::error_active: return "error_active";
    case BusState::error_warning: return "error_warning";
    case BusState::error_passive: return "error_passive";
    case BusState::bus_off: return "bus_off";
    case BusState::stopped: return "stopped";
  }
  return "unknown";
}

BusState bus_state_after_error_frame(BusState before, const CanFrame& err) noexcept {
  if (!err.is_error()) return before;
  const std::uint32_t cls = err.can_id & CAN_ERR_MASK;
  if (cls & CAN_ERR_BUSOFF) return BusState::bus_off;
  if (cls & CAN_ERR_RESTARTED) return BusState::error_active;
  if (cls & CAN_ERR_CRTL) {
    const std::uint8_t c = err.len > 1 ? err.data[1] : 0;
    if (c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) return BusState::error_passive;
    if (c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) return BusState::error_warning;
    if (c & CAN_ERR_CRTL_ACTIVE) return BusState::error_active;
  }
  return before == BusState::stopped ? BusState::error_active : before;
}

CanFrame make_error_frame_for_state(BusState s) noexcept {
  CanFrame f;
  f.len = CAN_ERR_DLC;
  switch (s) {
    case BusState::bus_off: f.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF; break;
    case BusState::error_passive:
      f.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
      f.data[1] = CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE;
      break;
    case BusState::error_warning:
      f.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
      f.data[1] = CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING;
      break;
    case BusState::error_active:
    case BusState::stopped: f.can_id = CAN_ERR_FLAG | CAN_ERR_RESTARTED; break;
  }
  return f;
}

RecvResult account_received(const CanFrame& f, BusState& state, CanBusCounters& counters) noexcept {
  if (f.is_error()) {
    const BusState before = state;
    state = bus_state_after_error_frame(state, f);
    if (state == BusState::bus_off && before != BusState::bus_off) ++counters.bus_off_events;
    ++counters.rx_error_frames;
    return RecvResult::error_frame;
  }
  ++counters.rx_frames;
  return RecvResult::frame;
}

}  // namespace crease::drivers
