#include "drivers/protocol/arm_protocol.h"

#include "drivers/protocol/pdo_frame.h"

namespace crease::drivers::arm {
using namespace wire;
using pdo::check_fd;
using pdo::sealed_fd;

CanFrame encode(std::uint8_t node, const Command& c) noexcept {
  std::uint8_t b[kCommandLen] = {};
  put_u16(b, c.seq);
  put_u16(b + 2, c.controlword);
  b[4] = c.mode;
  put_fixed_array<std::int32_t>(b + 8, c.position_rad, kJoints, kPositionUnitRad);
  put_fixed_array<std::int16_t>(b + 36, c.velocity_rad_s, kJoints, kVelocityUnitRadS);
  return sealed_fd(canopen::kRpdo1Base + node, b, kCommandLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Command& out) noexcept {
  const Decode d = check_fd(f, canopen::kRpdo1Base + node, kCommandLen);
  if (d != Decode::ok) return d;
  const std::uint8_t mode = f.data[4];
  if (mode != kModeCyclicPosition && mode != kModeCyclicVelocity) return Decode::bad_format;
  out.seq = get_u16(f.data);
  out.controlword = get_u16(f.data + 2);
  out.mode = mode;
  get_fixed_array<std::int32_t>(f.data + 8, out.position_rad, kJoints, kPositionUnitRad);
  get_fixed_array<std::int16_t>(f.data + 36, out.velocity_rad_s, kJoints, kVelocityUnitRadS);
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
  put_fixed_array<std::int32_t>(b + 12, s.position_rad, kJoints, kPositionUnitRad);
  put_fixed_array<std::int16_t>(b + 40, s.velocity_rad_s, kJoints, kVelocityUnitRadS);
  b[54] = s.sync_counter;
  b[55] = static_cast<std::uint8_t>(s.nmt);
  return sealed_fd(canopen::kTpdo1Base + node, b, kStatusLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Status& out) noexcept {
  canopen::NmtState nmt{};
  const Decode d = pdo::check_status_fd(f, canopen::kTpdo1Base + node, kStatusLen, 55, nmt);
  if (d != Decode::ok) return d;
  out.cmd_seq = get_u16(f.data);
  out.statusword = get_u16(f.data + 2);
  out.device_time_us = get_u32(f.data + 4);
  out.valid = f.data[8] & 0x7F;
  out.mode = f.data[9];
  out.error_code = get_u16(f.data + 10);
  get_fixed_array<std::int32_t>(f.data + 12, out.position_rad, kJoints, kPositionUnitRad);
  get_fixed_array<std::int16_t>(f.data + 40, out.velocity_rad_s, kJoints, kVelocityUnitRadS);
  out.sync_counter = f.data[54];
  out.nmt = nmt;
  return Decode::ok;
}

}  // namespace crease::drivers::arm
