#include "drivers/protocol/hand_protocol.h"

#include "drivers/protocol/wire.h"

namespace crease::drivers::hand {
namespace {
using namespace wire;

CanFrame sealed_fd(std::uint32_t id, std::uint8_t* b, std::size_t len) {
  seal(b, len);
  return CanFrame::fd(id, {b, len});
}

// Common checks: identifier, FD, exact length, CRC.
Decode check(const CanFrame& f, std::uint32_t id, std::size_t len) {
  if (f.is_error() || f.is_extended() || f.is_rtr() || f.id() != id) return Decode::not_mine;
  if (!f.is_fd() || f.len != len) return Decode::bad_format;
  return sealed_ok(f.data, len) ? Decode::ok : Decode::bad_crc;
}
}  // namespace

CanFrame encode(std::uint8_t node, const Command& c) noexcept {
  std::uint8_t b[kCommandLen] = {};
  put_u16(b, c.seq);
  b[2] = c.flags;
  for (int j = 0; j < kJoints; ++j) put_i16(b + 4 + 2 * j, to_fixed<std::int16_t>(c.target_rad[j], kAngleUnitRad));
  return sealed_fd(canopen::kRpdo1Base + node, b, kCommandLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Command& out) noexcept {
  const Decode d = check(f, canopen::kRpdo1Base + node, kCommandLen);
  if (d != Decode::ok) return d;
  out.seq = get_u16(f.data);
  out.flags = f.data[2];
  for (int j = 0; j < kJoints; ++j) out.target_rad[j] = static_cast<float>(get_i16(f.data + 4 + 2 * j) * kAngleUnitRad);
  return Decode::ok;
}

CanFrame encode(std::uint8_t node, const Stiffness& s) noexcept {
  std::uint8_t b[kStiffnessLen] = {};
  put_u16(b, s.seq);
  for (int j = 0; j < kJoints; ++j)
    put_u16(b + 4 + 2 * j, to_fixed<std::uint16_t>(s.stiffness_nm_per_rad[j], kStiffnessUnit));
  return sealed_fd(canopen::kRpdo2Base + node, b, kStiffnessLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Stiffness& out) noexcept {
  const Decode d = check(f, canopen::kRpdo2Base + node, kStiffnessLen);
  if (d != Decode::ok) return d;
  out.seq = get_u16(f.data);
  for (int j = 0; j < kJoints; ++j)
    out.stiffness_nm_per_rad[j] = static_cast<float>(get_u16(f.data + 4 + 2 * j) * kStiffnessUnit);
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
  for (int j = 0; j < kJoints; ++j) put_i16(b + 16 + 2 * j, to_fixed<std::int16_t>(s.position_rad[j], kAngleUnitRad));
  return sealed_fd(canopen::kTpdo1Base + node, b, kStatusLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Status& out) noexcept {
  const Decode d = check(f, canopen::kTpdo1Base + node, kStatusLen);
  if (d != Decode::ok) return d;
  const std::uint8_t nmt = f.data[4];
  if (nmt != 0x00 && nmt != 0x04 && nmt != 0x05 && nmt != 0x7F) return Decode::bad_format;
  out.cmd_seq = get_u16(f.data);
  out.stiff_seq = get_u16(f.data + 2);
  out.nmt = static_cast<canopen::NmtState>(nmt);
  out.flags = f.data[5];
  out.sync_counter = f.data[6];
  out.device_time_us = get_u32(f.data + 8);
  out.valid = get_u32(f.data + 12) & 0xFFFFFu;
  for (int j = 0; j < kJoints; ++j) out.position_rad[j] = static_cast<float>(get_i16(f.data + 16 + 2 * j) * kAngleUnitRad);
  return Decode::ok;
}

CanFrame encode(std::uint8_t node, const Pressure& p) noexcept {
  std::uint8_t b[kPressureLen] = {};
  put_u16(b, p.cmd_seq);
  b[2] = p.sync_counter;
  b[3] = static_cast<std::uint8_t>(p.valid & 0x1F);
  put_u32(b + 4, p.device_time_us);
  for (int k = 0; k < kPressureSensors; ++k)
    put_u16(b + 8 + 2 * k, to_fixed<std::uint16_t>(p.pressure_kpa[k], kPressureUnitKpa));
  return sealed_fd(canopen::kTpdo2Base + node, b, kPressureLen);
}

Decode decode(std::uint8_t node, const CanFrame& f, Pressure& out) noexcept {
  const Decode d = check(f, canopen::kTpdo2Base + node, kPressureLen);
  if (d != Decode::ok) return d;
  out.cmd_seq = get_u16(f.data);
  out.sync_counter = f.data[2];
  out.valid = f.data[3] & 0x1F;
  out.device_time_us = get_u32(f.data + 4);
  for (int k = 0; k < kPressureSensors; ++k)
    out.pressure_kpa[k] = static_cast<float>(get_u16(f.data + 8 + 2 * k) * kPressureUnitKpa);
  return Decode::ok;
}

}  // namespace crease::drivers::hand
