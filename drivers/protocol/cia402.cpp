#include "drivers/protocol/cia402.h"

namespace crease::drivers::cia402 {

const char* to_string(State s) noexcept {
  switch (s) {
    case State::not_ready_to_switch_on: return "not_ready_to_switch_on";
    case State::switch_on_disabled: return "switch_on_disabled";
    case State::ready_to_switch_on: return "ready_to_switch_on";
    case State::switched_on: return "switched_on";
    case State::operation_enabled: return "operation_enabled";
    case State::quick_stop_active: return "quick_stop_active";
    case State::fault_reaction_active: return "fault_reaction_active";
    case State::fault: return "fault";
  }
  return "unknown";
}

std::uint16_t statusword(State s) noexcept {
  switch (s) {
    case State::not_ready_to_switch_on: return 0x0000;
    case State::switch_on_disabled: return 0x0040;
    case State::ready_to_switch_on: return 0x0021;
    case State::switched_on: return 0x0033;
    case State::operation_enabled: return 0x0037;
    case State::quick_stop_active: return 0x0017;
    case State::fault_reaction_active: return 0x001F;
    case State::fault: return 0x0008;
  }
  return 0;
}

State state_from_statusword(std::uint16_t sw) noexcept {
  if ((sw & 0x004F) == 0x0000) return State::not_ready_to_switch_on;
  if ((sw & 0x004F) == 0x0040) return State::switch_on_disabled;
  if ((sw & 0x006F) == 0x0021) return State::ready_to_switch_on;
  if ((sw & 0x006F) == 0x0023) return State::switched_on;
  if ((sw & 0x006F) == 0x0027) return State::operation_enabled;
  if ((sw & 0x006F) == 0x0007) return State::quick_stop_active;
  if ((sw & 0x004F) == 0x000F) return State::fault_reaction_active;
  if ((sw & 0x004F) == 0x0008) return State::fault;
  return State::not_ready_to_switch_on;
}

void Machine::step(std::uint16_t cw, bool fault_condition) noexcept {
  const bool reset_edge = (cw & kCwFaultReset) && !last_reset_bit_;
  last_reset_bit_ = (cw & kCwFaultReset) != 0;
  if (state_ == State::fault_reaction_active) {
    state_ = State::fault;
    return;
  }
  if (state_ == State::fault) {
    if (reset_edge && !fault_condition) state_ = State::switch_on_disabled;
    return;
  }
  if (fault_condition) {
    state_ = State::fault_reaction_active;
    return;
  }
  const bool ev = cw & kCwEnableVoltage, qs = cw & kCwQuickStop, so = cw & kCwSwitchOn,
             eo = cw & kCwEnableOperation;
  const bool shutdown = ev && qs && !so;          // xxxx x110
  const bool switch_on = ev && qs && so && !eo;   // xxxx 0111
  const bool enable = ev && qs && so && eo;       // xxxx 1111
  const bool disable_voltage = !ev;               // xxxx xx0x
  const bool quick_stop = ev && !qs;              // xxxx x01x
  switch (state_) {
    case State::not_ready_to_switch_on: state_ = State::switch_on_disabled; break;
    case State::switch_on_disabled:
      if (shutdown) state_ = State::ready_to_switch_on;
      break;
    case State::ready_to_switch_on:
      if (switch_on) state_ = State::switched_on;
      else if (enable) state_ = State::operation_enabled;  // transition 2+3+4 shortcut allowed
      else if (disable_voltage || quick_stop) state_ = State::switch_on_disabled;
      break;
    case State::switched_on:
      if (enable) state_ = State::operation_enabled;
      else if (shutdown) state_ = State::ready_to_switch_on;
      else if (disable_voltage || quick_stop) state_ = State::switch_on_disabled;
      break;
    case State::operation_enabled:
      if (quick_stop) state_ = State::quick_stop_active;
      else if (switch_on) state_ = State::switched_on;
      else if (shutdown) state_ = State::ready_to_switch_on;
      else if (disable_voltage) state_ = State::switch_on_disabled;
      break;
    case State::quick_stop_active:
      if (disable_voltage) state_ = State::switch_on_disabled;
      break;
    case State::fault_reaction_active:
    case State::fault: break;
  }
}

}  // namespace crease::drivers::cia402
