// Port payloads of one hand's force controller (plugins/force_controller):
//   `hand_control_status` (latest): the mode, the force target and measurement, settled, why it
//                                   holds or retreats, the counters of refused goals;
//   `hand_control_event` (queue):   faults (a fingertip over its hard force limit, bad input)
//                                   and mode changes, in order.
// Fingers ff mf rf lf th (bit f), forces N, times CLOCK_MONOTONIC ns.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/hand_goal.h"
#include "core/port_types/payload_layout.h"

namespace crease {

// Why the controller stopped adding force (it then holds or retreats, its parameter `on_bad_input`).
enum class HandInhibit : std::uint8_t {
  none = 0,
  hand_state_fault = 1,   // hand_state health fault
  hand_state_stale = 2,   // hand_state degraded or not fresh for longer than the bound
  tactile_fault = 3,      // the tactile input's health fault (right hand's taxels)
  tactile_stale = 4,      // no tactile sample for longer than the bound
  force_limit = 5,        // a fingertip over force_limit_n: always a retreat
};

struct HandControlStatus {
  static constexpr char kPortType[] = "crease.HandControlStatus";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr int kFingers = 5;

  std::int64_t timestamp_ns = 0;
  std::int64_t settled_since_ns = 0;     // force mode: since when |error| stayed in the band; 0 if not
  std::uint64_t goals_accepted = 0;
  std::uint64_t goals_refused = 0;       // GoalRefusal: every reason counted here
  std::uint64_t inhibits = 0;            // times it stopped adding force (a new reason each)
  float force_target_n = 0;              // the ramped target this cycle
  float force_goal_n = 0;                // where the ramp ends
  float force_n[kFingers] = {};          // measured per fingertip (calibrated)
  float max_step_rad = 0;                // largest commanded joint change this cycle
  std::uint32_t goal_id = 0;             // of the goal being executed
  HandMode mode = HandMode::hold;
  HandInhibit inhibit = HandInhibit::none;
  std::uint8_t fingers = 0;              // fingers under force control
  std::uint8_t settled = 0;              // 1: |error| in the band for the hold time
  std::uint8_t saturated = 0;            // bit f: finger f's flexion at its limit
  std::uint8_t commanding = 0;           // 1: hand_command written (a hand_state has been seen)
  std::uint8_t last_refusal = 0;         // GoalRefusal of the last refused goal
  std::uint8_t limp = 0;                 // 1: commanding enable 0 (zero stiffness) until a first goal (`start: limp`)

  [[nodiscard]] bool all_finite() const {
    if (!std::isfinite(force_target_n) || !std::isfinite(force_goal_n) || !std::isfinite(max_step_rad)) return false;
    for (float f : force_n)
      if (!std::isfinite(f)) return false;
    return true;
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(HandControlStatus, 88, 8);

// Why a goal was refused: a non-finite value, a mode that is not a goal's, a force, ramp or
// stiffness out of range, a force goal with no finger to press, or inputs that are bad now
// (or a fingertip still over its force limit).
enum class GoalRefusal : std::uint8_t { none = 0, non_finite = 1, bad_mode = 2, out_of_range = 3, no_fingers = 4, inputs_bad = 5 };

struct HandControlEvent {
  static constexpr char kPortType[] = "crease.HandControlEvent";
  static constexpr std::uint32_t kPortVersion = 1;
  enum Kind : std::uint8_t { mode_changed = 0, inhibited = 1, force_limit_fault = 2, goal_refused = 3 };

  std::int64_t timestamp_ns = 0;
  float value = 0;                // force_limit_fault: the force (N); else 0
  Kind kind = mode_changed;
  HandMode mode = HandMode::hold; // the mode after the event
  HandInhibit inhibit = HandInhibit::none;
  std::uint8_t finger = 0;        // force_limit_fault: the fingertip
};

CREASE_PORT_PAYLOAD_LAYOUT(HandControlEvent, 16, 8);

}  // namespace crease
