// What the bridge's checks found in a sample taken from DDS.
#pragma once

#include <cstdint>

namespace crease::dds_bridge {

enum class SampleCheck : std::uint8_t {
  ok,         // converted; may be written into the port
  malformed,  // a non-finite number or a value out of its range: dropped and counted
  oversized,  // more entries than the port payload holds: dropped and counted
};

}  // namespace crease::dds_bridge
