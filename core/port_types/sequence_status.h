// Port payload `sequence_status` (latest): where a folding sequence (plugins/fold_sequence) is,
// for creasectl status, the console and the report: the state path, how long it has been in
// that state, the last transition and why, and whether it is running, paused, done or aborted.
// The daemon shows every latest port of this type and knows nothing of the states' meaning.
// Texts are NUL-terminated within their arrays. Times CLOCK_MONOTONIC ns, durations s.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct SequenceStatus {
  static constexpr char kPortType[] = "crease.SequenceStatus";
  static constexpr std::uint32_t kPortVersion = 1;

  enum Phase : std::uint8_t {
    idle = 0,     // not started
    running = 1,
    paused = 2,   // by the operator, or between two states in step mode
    done = 3,     // the fold finished
    aborted = 4,  // the safe retreat finished (or is running: state path under "abort")
  };

  std::int64_t timestamp_ns = 0;
  std::int64_t state_since_ns = 0;  // when the current (innermost) state was entered
  double time_in_state_s = 0;       // in the current state, pauses not counted
  std::uint32_t transitions = 0;    // since activation
  std::uint32_t aborts = 0;         // times the abort superstate was entered
  std::uint16_t state = 0;          // the innermost state's id (plugins/fold_sequence/states.h)
  std::uint8_t via = 0;             // follow_via's index
  std::uint8_t phase = idle;
  std::uint8_t step_mode = 0;       // 1: pauses before every transition (sequence step)
  std::uint8_t abort_reason = 0;    // fold_sequence's Reason of the last abort (0: none)
  std::uint8_t reserved[2] = {};
  char path[64] = {};               // e.g. "fold/bend/follow_via[3]"
  char why[64] = {};                // the last transition's reason, e.g. "arm_l reached"
  char fold[16] = {};               // the fold's name (its sequence file's `name`)

  [[nodiscard]] bool all_finite() const { return std::isfinite(time_in_state_s); }
};

CREASE_PORT_PAYLOAD_LAYOUT(SequenceStatus, 184, 8);

}  // namespace crease
