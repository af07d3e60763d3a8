// Port payload `hand_goal` (queue): what one hand's force controller (plugins/force_controller,
// the hand's one `hand_command` writer) is asked to do next, from the folding sequence or a test:
//   posture  move the joints to target_rad (ramped over ramp_s, rate limited) at the given
//            stiffness, and hold there;
//   hold     keep the commanded targets where they are;
//   force    press the fingers in `fingers` (or, when 0, those in contact now; the thumb never)
//            with force_n each (N), the target ramped from the force measured now over ramp_s
//            (seed 000 Eq. 6).
// A goal with a non-finite value, an unknown mode, a negative force or ramp is refused and
// counted on `hand_control_status`: the hand goes on with what it did. No all_finite() here on
// purpose: the controller, not the writer's port, refuses and counts such goals (they may come
// over a bridge). Angles rad in drivers/README.md §3's joint order, stiffness N m/rad.
#pragma once

#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

enum class HandMode : std::uint8_t {
  posture = 0,
  hold = 1,
  force = 2,
  retreat = 3,  // not a goal: the controller's own safe action (status only)
};

struct HandGoal {
  static constexpr char kPortType[] = "crease.HandGoal";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr int kJoints = 20;

  std::int64_t timestamp_ns = 0;
  std::uint32_t id = 0;                      // echoed on the status port
  HandMode mode = HandMode::hold;
  std::uint8_t fingers = 0;                  // force: bit f = finger f (ff mf rf lf; bit 4 th ignored)
  std::uint8_t set_stiffness = 0;            // posture: 1 = apply stiffness_nm_per_rad
  std::uint8_t reserved = 0;
  float force_n = 0;                         // force: per fingertip, N
  float ramp_s = 0;                          // posture and force: ramp duration, s (0: at once, rate limited)
  float target_rad[kJoints] = {};            // posture
  float stiffness_nm_per_rad[kJoints] = {};  // posture, with set_stiffness
};

CREASE_PORT_PAYLOAD_LAYOUT(HandGoal, 184, 8);

}  // namespace crease
