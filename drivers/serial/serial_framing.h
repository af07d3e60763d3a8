// Framing of the serial links (see drivers/README.md, "Serial framing"):
//   body  = seq u8 | type u8 | len u16 LE | payload[len] | crc32c u32 LE (over seq..payload)
//   wire  = 0x00 COBS(body) 0x00   (the leading 0x00 ends any garbage before the frame)
// A receiver resynchronises on the next 0x00: garbage, an over-long run, bad COBS or a bad CRC
// cost at most the frame they hit. Everything here is RT-safe (fixed buffers, no allocation).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "drivers/serial/cobs.h"

namespace crease::drivers {

inline constexpr std::size_t kSerialMaxPayload = 512;
inline constexpr std::size_t kSerialHeader = 4;
inline constexpr std::size_t kSerialMaxBody = kSerialHeader + kSerialMaxPayload + 4;
inline constexpr std::size_t kSerialMaxWire = cobs_max_encoded(kSerialMaxBody) + 2;

struct SerialFrame {
  std::uint8_t seq = 0;
  std::uint8_t type = 0;
  std::uint16_t len = 0;
  std::uint8_t payload[kSerialMaxPayload] = {};
  [[nodiscard]] std::span<const std::uint8_t> bytes() const noexcept { return {payload, len}; }
};

// Encodes one frame (with both delimiters) into out (>= kSerialMaxWire bytes is always
// enough). Returns the wire length, or 0 if the payload exceeds kSerialMaxPayload.
[[nodiscard]] std::size_t serial_encode(std::uint8_t seq, std::uint8_t type,
                                        std::span<const std::uint8_t> payload,
                                        std::span<std::uint8_t> out) noexcept;

struct SerialDeframerStats {
  std::uint64_t frames = 0;
  std::uint64_t crc_errors = 0;
  std::uint64_t cobs_errors = 0;    // invalid stuffing or length field mismatch
  std::uint64_t overlong = 0;       // more than kSerialMaxWire bytes without a delimiter
  std::uint64_t seq_gaps = 0;       // frames whose seq is not previous + 1 (lost frames)
  std::uint64_t bytes_discarded = 0;
};

class SerialDeframer {
 public:
  // Feeds one byte; returns true when it completed a valid frame, now in `out`.
  [[nodiscard]] bool push(std::uint8_t byte, SerialFrame& out) noexcept;
  // Feeds bytes until one frame completes; returns the number of bytes consumed (call again
  // with the rest). *got tells whether `out` holds a new frame. Same result as push() on each
  // byte, scanning for delimiters with memchr and copying whole runs.
  std::size_t feed(std::span<const std::uint8_t> bytes, SerialFrame& out, bool* got) noexcept;
  [[nodiscard]] const SerialDeframerStats& stats() const noexcept { return stats_; }
  void reset() noexcept;

 private:
  void take_run(const std::uint8_t* p, std::size_t k) noexcept;  // k non-zero bytes
  bool end_run(SerialFrame& out) noexcept;                        // at a delimiter
  std::uint8_t buf_[kSerialMaxWire] = {};
  std::size_t n_ = 0;
  bool discarding_ = false;  // after an over-long run: drop bytes until the next 0x00
  bool have_seq_ = false;
  std::uint8_t last_seq_ = 0;
  SerialDeframerStats stats_;
};

}  // namespace crease::drivers
