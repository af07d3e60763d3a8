#include "drivers/protocol/hand_protocol.h"

#include "drivers/protocol/pdo_frame.h"

namespace crease::drivers::hand {
using namespace wire;
using pdo::check_fd;
using pdo::sealed_fd;

CanFrame encode(std::uint8_t node, const Command& c) noexcept {
  std::uint8_t b[kCommandLen] = {};
  put_u16(b, c.seq);
  b[2] = c.flags;
  put_fixed_array<std::int16_t>(b + 4, c.target_rad, kJoints, kAngleUnitRad);
  return sealed_fd(canopen::kRpdo1Base + node, b, kCommandLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Command& out) noexcept {
  const Decode d = check_fd(f, canopen::kRpdo1Base + node, kCommandLen);
  if (d != Decode::ok) return d;
  out.seq = get_u16(f.data);
  out.flags = f.data[2];
  get_fixed_array<std::int16_t>(f.data + 4, out.target_rad, kJoints, kAngleUnitRad);
  return Decode::ok;
}

CanFrame encode(std::uint8_t node, const Stiffness& s) noexcept {
  std::uint8_t b[kStiffnessLen] = {};
  put_u16(b, s.seq);
  put_fixed_array<std::uint16_t>(b + 4, s.stiffness_nm_per_rad, kJoints, kStiffnessUnit);
  return sealed_fd(canopen::kRpdo2Base + node, b, kStiffnessLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Stiffness& out) noexcept {
  const Decode d = check_fd(f, canopen::kRpdo2Base + node, kStiffnessLen);
  if (d != Decode::ok) return d;
  out.seq = get_u16(f.data);
  get_fixed_array<std::uint16_t>(f.data + 4, out.stiffness_nm_per_rad, kJoints, kStiffnessUnit);
  return Decode::ok;
}

CanFrame encode(std::uint8_t node, const Status& s) noexcept {
  std::uint8_t b[kStatusLen] = {};
  put_u16(b, s.cmd_seq);
  put_u16(b + 2, s.stiff_seq);
  b[4] = static_cast<std::uint8_t>(s.nmt);
  b[5] = s.flags;
  b[6] = s.sync_counter;
  put_u32(b + 8, s.device_time_us);
  put_u32(b + 12, s.valid & 0xFFFFFu);
  put_fixed_array<std::int16_t>(b + 16, s.position_rad, kJoints, kAngleUnitRad);
  return sealed_fd(canopen::kTpdo1Base + node, b, kStatusLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Status& out) noexcept {
  canopen::NmtState nmt{};
  const Decode d = pdo::check_status_fd(f, canopen::kTpdo1Base + node, kStatusLen, 4, nmt);
  if (d != Decode::ok) return d;
  out.cmd_seq = get_u16(f.data);
  out.stiff_seq = get_u16(f.data + 2);
  out.nmt = nmt;
  out.flags = f.data[5];
  out.sync_counter = f.data[6];
  out.device_time_us = get_u32(f.data + 8);
  out.valid = get_u32(f.data + 12) & 0xFFFFFu;
  get_fixed_array<std::int16_t>(f.data + 16, out.position_rad, kJoints, kAngleUnitRad);
  return Decode::ok;
}

CanFrame encode(std::uint8_t node, const Pressure& p) noexcept {
  std::uint8_t b[kPressureLen] = {};
  put_u16(b, p.cmd_seq);
  b[2] = p.sync_counter;
  b[3] = static_cast<std::uint8_t>(p.valid & 0x1F);
  put_u32(b + 4, p.device_time_us);
  put_fixed_array<std::uint16_t>(b + 8, p.pressure_kpa, kPressureSensors, kPressureUnitKpa);
  return sealed_fd(canopen::kTpdo2Base + node, b, kPressureLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Pressure& out) noexcept {
  const Decode d = check_fd(f, canopen::kTpdo2Base + node, kPressureLen);
  if (d != Decode::ok) return d;
  out.cmd_seq = get_u16(f.data);
  out.sync_counter = f.data[2];
  out.valid = f.data[3] & 0x1F;
  out.device_time_us = get_u32(f.data + 4);
  get_fixed_array<std::uint16_t>(f.data + 8, out.pressure_kpa, kPressureSensors, kPressureUnitKpa);
  return Decode::ok;
}

}  // namespace crease::drivers::hand
