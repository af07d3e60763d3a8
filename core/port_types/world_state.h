// Port payload `world_state`: the simulated world's truth beside its sheet (plugins/sim_world),
// for scoring and views: per hand the fingertips' pad frames and contact forces, the palm's,
// the joint angles the hand's compliant joints settled at; the sheet's contact area with the
// table; how deep each arm reaches under the table; the world's time and its counters of refused
// or repaired input.
// World frame, mm, N, rad (names carry the units).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct WorldFingertip {
  float position_mm[3] = {};  // the tactile pad's frame (robot_model ToolFrame <f>pad): origin
  float rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // its axes, row-major (z: the pad's outward normal)
  float force_n[3] = {};      // total contact force on the fingertip (pad, back, distal cover)
  float normal_force_n = 0;   // its part along the contacts' normals (what presses)
  float tangential_force_n = 0;  // the magnitude of its friction part
  std::uint8_t contact = 0;   // 1: touching the sheet or the table this step
};

struct WorldHand {
  static constexpr int kJoints = 20;
  static constexpr int kFingertips = 5;  // ff mf rf lf th
  WorldFingertip tip[kFingertips];
  float palm_force_n[3] = {};
  std::uint8_t palm_contact = 0;
  float joint_rad[kJoints] = {};       // the joints' angles: target plus deflection (what the hand measures)
  float deflection_rad[kJoints] = {};  // joint angle - commanded target
};

struct WorldState {
  static constexpr char kPortType[] = "crease.WorldState";
  static constexpr std::uint32_t kPortVersion = 2;
  static constexpr int kSides = 2;  // right, left

  std::int64_t timestamp_ns = 0;  // CLOCK_MONOTONIC time of the step
  std::uint64_t step = 0;         // world steps since the start
  double time_s = 0;              // world time: step x dt
  WorldHand hand[kSides];
  float sheet_table_contact_area_mm2 = 0;
  // Per side, how deep (mm) the arm's links and the wrist and forearm (kinematic, unlike the
  // compliant hand) reach under the table's top over its extent this step: 0 where clear. The
  // world moves them through the table; a real arm would hit it.
  float under_table_mm[kSides] = {};
  // Counters since the start: joint targets clamped to the URDF limits, non-finite targets
  // refused, negative or non-finite stiffness refused, commands slowed to the joints' velocity
  // limits, steps rolled back after a non-finite result.
  std::uint32_t clamped_targets = 0;
  std::uint32_t refused_targets = 0;
  std::uint32_t refused_stiffness = 0;
  std::uint32_t rate_limited = 0;
  std::uint32_t rollbacks = 0;

  [[nodiscard]] bool all_finite() const {
    for (const WorldHand& h : hand) {
      for (const WorldFingertip& t : h.tip) {
        for (float v : t.position_mm)
          if (!std::isfinite(v)) return false;
        for (float v : t.force_n)
          if (!std::isfinite(v)) return false;
      }
      for (int j = 0; j < WorldHand::kJoints; ++j)
        if (!std::isfinite(h.joint_rad[j])) return false;
    }
    for (float v : under_table_mm)
      if (!std::isfinite(v)) return false;
    return std::isfinite(sheet_table_contact_area_mm2) && std::isfinite(time_s);
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(WorldState, 1128, 8);

}  // namespace crease
