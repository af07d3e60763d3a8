#include "drivers/protocol/arm_protocol.h"

#include "drivers/protocol/wire.h"

namespace crease::drivers::arm {
namespace {
using namespace wire;
Decode check(const CanFrame& f, std::uint32_t id, std::size_t len) {
  if (f.is_error() || f.is_extended() || f.is_rtr() || f.id() != id) return Decode::not_mine;
  if (!f.is_fd() || f.len != len) return Decode::bad_format;
  return sealed_ok(f.data, len) ? Decode::ok : Decode::bad_crc;
}
}  // namespace

CanFrame encode(std::uint8_t node, const Command& c) noexcept {
  std::uint8_t b[kCommandLen] = {};
  put_u16(b, c.seq);
  put_u16(b + 2, c.controlword);
  b[4] = c.mode;
  for (int j = 0; j < kJoints; ++j) {
    put_i32(b + 8 + 4 * j, to_fixed<std::int32_t>(c.position_rad[j], kPositionUnitRad));
    put_i16(b + 36 + 2 * j, to_fixed<std::int16_t>(c.velocity_rad_s[j], kVelocityUnitRadS));
  }
  seal(b, kCommandLen);
  return CanFrame::fd(canopen::kRpdo1Base + node, b);
}

Decode decode(std::uint8_t node, const CanFrame& f, Command& out) noexcept {
  const Decode d = check(f, canopen::kRpdo1Base + node, kCommandLen);
  if (d != Decode::ok) return d;
  const std::uint8_t mode = f.data[4];
  if (mode != kModeCyclicPosition && mode != kModeCyclicVelocity) return Decode::bad_format;
  out.seq = get_u16(f.data);
  out.controlword = get_u16(f.data + 2);
  out.mode = mode;
  for (int j = 0; j < kJoints; ++j) {
    out.position_rad[j] = static_cast<float>(get_i32(f.data + 8 + 4 * j) * kPositionUnitRad);
    out.velocity_rad_s[j] = static_cast<float>(get_i16(f.data + 36 + 2 * j) * kVelocityUnitRadS);
  }
  return Decode::ok;
}

CanFrame encode(std::uint8_t node, const Status& s) noexcept {
  std::uint8_t b[kStatusLen] = {};
  put_u16(b, s.cmd_seq);
  put_u16(b + 2, s.statusword);
  put_u32(b + 4, s.device_time_us);
  b[8] = static_cast<std::uint8_t>(s.valid & 0x7F);
  b[9] = s.mode;
  put_u16(b + 10, s.error_code);
  for (int j = 0; j < kJoints; ++j) {
    put_i32(b + 12 + 4 * j, to_fixed<std::int32_t>(s.position_rad[j], kPositionUnitRad));
    put_i16(b + 40 + 2 * j, to_fixed<std::int16_t>(s.velocity_rad_s[j], kVelocityUnitRadS));
  }
  b[54] = s.sync_counter;
  b[55] = static_cast<std::uint8_t>(s.nmt);
  seal(b, kStatusLen);
  return CanFrame::fd(canopen::kTpdo1Base + node, b);
}

Decode decode(std::uint8_t node, const CanFrame& f, Status& out) noexcept {
  const Decode d = check(f, canopen::kTpdo1Base + node, kStatusLen);
  if (d != Decode::ok) return d;
  const std::uint8_t nmt = f.data[55];
  if (nmt != 0x00 && nmt != 0x04 && nmt != 0x05 && nmt != 0x7F) return Decode::bad_format;
  out.cmd_seq = get_u16(f.data);
  out.statusword = get_u16(f.data + 2);
  out.device_time_us = get_u32(f.data + 4);
  out.valid = f.data[8] & 0x7F;
  out.mode = f.data[9];
  out.error_code = get_u16(f.data + 10);
  for (int j = 0; j < kJoints; ++j) {
    out.position_rad[j] = static_cast<float>(get_i32(f.data + 12 + 4 * j) * kPositionUnitRad);
    out.velocity_rad_s[j] = static_cast<float>(get_i16(f.data + 40 + 2 * j) * kVelocityUnitRadS);
  }
  out.sync_counter = f.data[54];
  out.nmt = static_cast<canopen::NmtState>(nmt);
  return Decode::ok;
}

}  // namespace crease::drivers::arm
