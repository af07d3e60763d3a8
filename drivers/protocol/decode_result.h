// Outcome of decoding one frame.
#pragma once

#include <cstdint>

namespace crease::drivers {

enum class Decode : std::uint8_t {
  ok,
  not_mine,    // another identifier / node / message type: not an error
  bad_format,  // right identifier, wrong length or frame kind (classic vs FD)
  bad_crc,     // the payload's CRC-32C does not match: the frame is corrupted
};

}  // namespace crease::drivers
