// Port payloads of one hand's contact controller (plugins/contact_controller, seed 000 Eq. 5),
// read by arm_motion as a motion's stop condition and by the force controller:
//   `contact_state` (latest): which fingers touch now, the deviation norm, since when;
//   `contact_event` (queue):  one record per onset or release, in order.
// Fingers in the order ff mf rf lf th (bit f of a mask). Times CLOCK_MONOTONIC ns, angles rad.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

// What detected a contact: the joints' deviation from the relaxed pose (Eq. 5), the tactile
// sensors (pressure above its tared baseline), or both.
enum ContactSource : std::uint8_t { contact_none = 0, contact_joints = 1, contact_tactile = 2 };

struct ContactState {
  static constexpr char kPortType[] = "crease.ContactState";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr int kFingers = 5;

  std::int64_t timestamp_ns = 0;   // the control cycle that computed it
  std::int64_t since_ns = 0;       // onset of the current contact; 0 while none
  std::uint64_t onsets = 0;        // contact onsets since the start (a counter a reader can watch)
  float deviation_rad = 0;         // ||theta - theta_ref||_P this cycle
  float threshold_rad = 0;         // the Delta theta_max it is compared with (enter threshold)
  float finger_deviation_rad[kFingers] = {};  // per finger, over the joints P selects
  std::uint8_t fingers = 0;        // bit f: finger f in contact (debounced, with hysteresis)
  std::uint8_t in_contact = 0;     // 1: any finger in contact
  std::uint8_t source = contact_none;  // ContactSource bits of the current contact
  std::uint8_t armed = 0;          // 1: theta_ref captured (hand settled), detection running
  std::uint8_t healthy = 0;        // 1: its inputs were fresh and healthy this cycle

  [[nodiscard]] bool all_finite() const {
    if (!std::isfinite(deviation_rad) || !std::isfinite(threshold_rad)) return false;
    for (float x : finger_deviation_rad)
      if (!std::isfinite(x)) return false;
    return true;
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(ContactState, 64, 8);

struct ContactEvent {
  static constexpr char kPortType[] = "crease.ContactEvent";
  static constexpr std::uint32_t kPortVersion = 1;

  std::int64_t timestamp_ns = 0;  // the cycle the (debounced) change was decided
  std::uint8_t fingers = 0;       // the fingers in contact after the change
  std::uint8_t onset = 0;         // 1: contact began, 0: released
  std::uint8_t source = contact_none;
};

CREASE_PORT_PAYLOAD_LAYOUT(ContactEvent, 16, 8);

}  // namespace crease
