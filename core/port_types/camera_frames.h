// Port payload `camera_frames`: a camera source announcing the frame set it just published.
// The pixels do not travel on this port (megabytes per set): they are in the frame channel named
// `channel` (core/frames, a port of kind `frames` that both ends bound at configure time).
#pragma once

#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct CameraFrames {
  static constexpr char kPortType[] = "crease.CameraFrames";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr std::uint32_t kChannelNameCapacity = 48;

  char channel[kChannelNameCapacity] = {};  // frame channel name, NUL-terminated
  std::uint64_t sequence = 0;    // channel sequence of the set (0 = nothing published yet)
  std::uint64_t frame = 0;       // the source's frame index
  std::int64_t stamp_ns = 0;     // CLOCK_MONOTONIC capture time of the set
  std::uint32_t cameras = 0;     // cameras in the set
  std::uint32_t valid_mask = 0;  // bit k: camera k delivered an image in this set
  std::uint32_t ended = 0;       // 1: the source has no more frames (a replay's end)
  std::uint32_t reserved = 0;
};

CREASE_PORT_PAYLOAD_LAYOUT(CameraFrames, 88, 8);

}  // namespace crease
