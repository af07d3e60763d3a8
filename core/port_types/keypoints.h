// Port payload `keypoints`: triangulated marker key-points of one vision frame.
// Each detected marker gives five key-points (its centre and four corners, seed 000 IV-A);
// a key-point seen by at least two cameras is triangulated and published here.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct Keypoint {
  float world_mm[3];       // triangulated position, world frame (z up, table origin), mm
  float sheet_mm[2];       // (u, v) on the sheet, mm (DESIGN.md sheet coordinates)
  float reproj_error_px;   // RMS reprojection error over the views used, pixels
  std::uint16_t marker_id; // dictionary id of the marker it belongs to
  std::uint8_t corner;     // 0 = centre, 1..4 = corners in detector order (TL, TR, BR, BL)
  std::uint8_t face;       // 0 = front (printed) face, 1 = back face
  std::uint32_t views;     // bit k set: camera k contributed
};

struct Keypoints {
  static constexpr char kPortType[] = "crease.Keypoints";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr std::uint32_t kCapacity = 512;

  std::int64_t timestamp_ns = 0;  // CLOCK_MONOTONIC capture time of the images
  std::uint64_t frame = 0;        // vision frame counter
  std::uint32_t count = 0;        // valid entries in points[0..count)
  std::uint32_t cameras_ok = 0;   // bit k set: camera k delivered an image this frame
  Keypoint points[kCapacity];

  [[nodiscard]] bool all_finite() const {
    if (count > kCapacity) return false;
    for (std::uint32_t i = 0; i < count; ++i) {
      const Keypoint& k = points[i];
      for (float x : k.world_mm)
        if (!std::isfinite(x)) return false;
      if (!std::isfinite(k.sheet_mm[0]) || !std::isfinite(k.sheet_mm[1]) ||
          !std::isfinite(k.reproj_error_px))
        return false;
    }
    return true;
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(Keypoint, 32, 4);
CREASE_PORT_PAYLOAD_LAYOUT(Keypoints, 16408, 8);

}  // namespace crease
