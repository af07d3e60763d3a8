// A CiA 402-like drive state machine (IEC 61800-7-201): controlword in, statusword out.
// Used by the simulated arm (device side) and by the arm driver to interpret statuswords.
#pragma once

#include <cstdint>

namespace crease::drivers::cia402 {

enum class State : std::uint8_t {
  not_ready_to_switch_on,
  switch_on_disabled,
  ready_to_switch_on,
  switched_on,
  operation_enabled,
  quick_stop_active,
  fault_reaction_active,
  fault,
};
[[nodiscard]] const char* to_string(State s) noexcept;

// Controlword bits and the standard commands.
inline constexpr std::uint16_t kCwSwitchOn = 0x0001, kCwEnableVoltage = 0x0002, kCwQuickStop = 0x0004,
                               kCwEnableOperation = 0x0008, kCwFaultReset = 0x0080;
inline constexpr std::uint16_t kCmdShutdown = 0x0006, kCmdSwitchOn = 0x0007, kCmdEnableOperation = 0x000F,
                               kCmdDisableVoltage = 0x0000, kCmdQuickStop = 0x0002,
                               kCmdDisableOperation = 0x0007, kCmdFaultReset = 0x0080;

// Statusword of a state (bits 0,1,2,3,5,6; bit 4 voltage enabled in the powered states).
[[nodiscard]] std::uint16_t statusword(State s) noexcept;
// State a statusword encodes (the standard's masks); not_ready_to_switch_on if none matches.
[[nodiscard]] State state_from_statusword(std::uint16_t sw) noexcept;

// Device-side machine. step() applies one controlword (fault reset acts on the rising edge of
// bit 7); raise_fault() enters fault_reaction_active, which completes to fault on the next step.
class Machine {
 public:
  void step(std::uint16_t controlword, bool fault_condition) noexcept;
  void raise_fault() noexcept { state_ = State::fault_reaction_active; }
  // Device-initiated quick stop (e.g. the command watchdog): operation enabled -> quick stop.
  void quick_stop() noexcept { if (state_ == State::operation_enabled) state_ = State::quick_stop_active; }
  void power_up() noexcept { if (state_ == State::not_ready_to_switch_on) state_ = State::switch_on_disabled; }
  [[nodiscard]] State state() const noexcept { return state_; }
  [[nodiscard]] bool operation_enabled() const noexcept { return state_ == State::operation_enabled; }

 private:
  State state_ = State::not_ready_to_switch_on;
  bool last_reset_bit_ = false;
};

}  // namespace crease::drivers::cia402
