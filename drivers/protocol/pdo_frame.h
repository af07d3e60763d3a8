// The CAN FD envelope every device PDO of the hand and arm protocols shares (drivers/README.md
// §1): standard 11-bit identifier, FD frame of an exact length, CRC-32C in the last 4 bytes.
// RT-safe.
#pragma once

#include <cstddef>
#include <cstdint>

#include "drivers/can/can_frame.h"
#include "drivers/protocol/canopen.h"
#include "drivers/protocol/decode_result.h"
#include "drivers/protocol/wire.h"

namespace crease::drivers::pdo {

// Seals b[0..len) with its CRC-32C trailer and wraps it in an FD frame with identifier id.
[[nodiscard]] inline CanFrame sealed_fd(std::uint32_t id, std::uint8_t* b, std::size_t len) noexcept {
  wire::seal(b, len);
  return CanFrame::fd(id, {b, len});
}

// The checks before a PDO's fields are read: not_mine for another identifier or an error /
// extended / remote frame, bad_format for a classic frame or the wrong length, bad_crc.
[[nodiscard]] inline Decode check_fd(const CanFrame& f, std::uint32_t id, std::size_t len) noexcept {
  if (f.is_error() || f.is_extended() || f.is_rtr() || f.id() != id) return Decode::not_mine;
  if (!f.is_fd() || f.len != len) return Decode::bad_format;
  return wire::sealed_ok(f.data, len) ? Decode::ok : Decode::bad_crc;
}

// check_fd for a device status, which also carries the device's NMT state at nmt_offset:
// bad_format when that byte is no NmtState; nmt is written only when the result is ok.
[[nodiscard]] inline Decode check_status_fd(const CanFrame& f, std::uint32_t id, std::size_t len, std::size_t nmt_offset,
                                            canopen::NmtState& nmt) noexcept {
  const Decode d = check_fd(f, id, len);
  if (d != Decode::ok) return d;
  if (!canopen::is_nmt_state(f.data[nmt_offset])) return Decode::bad_format;
  nmt = static_cast<canopen::NmtState>(f.data[nmt_offset]);
  return Decode::ok;
}

}  // namespace crease::drivers::pdo
