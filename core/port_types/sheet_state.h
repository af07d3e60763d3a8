// Port payloads of the sheet model (plugins/sheet_model):
//   sheet_state   (latest, out): node positions and normals, creases, per-link strain, quality;
//   target_points (latest, in):  world targets for sheet points (seed 001 Eq. 4 springs);
//   sheet_crease / sheet_memorize / sheet_reset (queue, in): model edits from the sequencer.
// Geometry in mm: world frame (z up, table origin); sheet coordinates (u, v) as in DESIGN.md.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct SheetState {
  static constexpr char kPortType[] = "crease.SheetState";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr std::uint32_t kMaxNodes = 64 * 64;
  static constexpr std::uint32_t kMaxLinks = 16384;
  static constexpr std::uint32_t kMaxCreases = 32;

  std::int64_t timestamp_ns = 0;   // CLOCK_MONOTONIC time the state refers to
  std::uint64_t step = 0;          // model steps since activation
  std::uint16_t nodes_u = 0;       // W
  std::uint16_t nodes_v = 0;       // H; nodes stored row by row (j outer, i inner)
  float width_mm = 0, height_mm = 0;
  std::uint32_t link_count = 0;    // valid entries of strain[] (links beyond kMaxLinks omitted)
  std::uint32_t crease_count = 0;
  // Quality: mean distance of observed sheet points to their observations (mm, after the
  // step; negative when nothing was observed), how many were used, and whether this state
  // was rolled back after a non-finite step.
  float fit_error_mm = -1;
  std::uint32_t observations = 0;
  std::uint32_t rollbacks = 0;     // since activation
  float position_mm[kMaxNodes][3];
  float normal[kMaxNodes][3];      // unit normal of the printed face
  float crease_mm[kMaxCreases][4]; // u0 v0 u1 v1
  std::int32_t crease_id[kMaxCreases];  // the id a SheetCreaseEvent remove names
  float strain[kMaxLinks];         // (length - rest) / rest

  [[nodiscard]] bool all_finite() const {
    const std::uint32_t n = static_cast<std::uint32_t>(nodes_u) * nodes_v;
    if (n > kMaxNodes || link_count > kMaxLinks || crease_count > kMaxCreases) return false;
    for (std::uint32_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(position_mm[i][c]) || !std::isfinite(normal[i][c])) return false;
    for (std::uint32_t k = 0; k < link_count; ++k)
      if (!std::isfinite(strain[k])) return false;
    return std::isfinite(fit_error_mm);
  }
};

struct TargetPoints {
  static constexpr char kPortType[] = "crease.TargetPoints";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr std::uint32_t kCapacity = 1024;
  // One target as it travels on the port (floats, mm); the model's own form, in doubles, is
  // sheet::TargetPoint (plugins/sheet_model/sheet_model.h).
  struct Point {
    float world_mm[3];  // world frame
    float sheet_mm[2];  // (u, v) on the sheet
  };
  std::int64_t timestamp_ns = 0;
  std::uint32_t count = 0;
  Point points[kCapacity];
  // Non-finite entries are tolerated here: the model drops them one by one.
};

struct SheetCreaseEvent {
  static constexpr char kPortType[] = "crease.SheetCreaseEvent";
  static constexpr std::uint32_t kPortVersion = 1;
  enum class Op : std::uint8_t { add = 0, remove = 1, clear = 2 };
  std::int64_t timestamp_ns = 0;
  Op op = Op::add;
  std::int32_t id = -1;            // remove: the crease's id (SheetState::crease_id)
  float a_mm[2] = {0, 0};          // add: segment end points, sheet mm
  float b_mm[2] = {0, 0};
};

struct SheetMemorizeEvent {
  static constexpr char kPortType[] = "crease.SheetMemorizeEvent";
  static constexpr std::uint32_t kPortVersion = 1;
  std::int64_t timestamp_ns = 0;
  bool whole_sheet = true;         // false: only links with both ends in [min, max]
  float min_mm[2] = {0, 0};
  float max_mm[2] = {0, 0};
};

struct SheetResetEvent {
  static constexpr char kPortType[] = "crease.SheetResetEvent";
  static constexpr std::uint32_t kPortVersion = 1;
  std::int64_t timestamp_ns = 0;
};

CREASE_PORT_PAYLOAD_LAYOUT(SheetState, 164528, 8);
CREASE_PORT_PAYLOAD_LAYOUT(TargetPoints::Point, 20, 4);
CREASE_PORT_PAYLOAD_LAYOUT(TargetPoints, 20496, 8);
CREASE_PORT_PAYLOAD_LAYOUT(SheetCreaseEvent, 32, 8);
CREASE_PORT_PAYLOAD_LAYOUT(SheetMemorizeEvent, 32, 8);
CREASE_PORT_PAYLOAD_LAYOUT(SheetResetEvent, 8, 8);

}  // namespace crease
