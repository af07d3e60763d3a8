#include "drivers/protocol/canopen.h"

#include "drivers/protocol/wire.h"

namespace crease::drivers::canopen {

CanFrame encode_nmt(NmtCommand cmd, std::uint8_t node) noexcept {
  const std::uint8_t b[2] = {static_cast<std::uint8_t>(cmd), node};
  return CanFrame::classic(kNmtId, b);
}

bool decode_nmt(const CanFrame& f, NmtCommand& cmd, std::uint8_t& node) noexcept {
  if (f.is_error() || f.is_extended() || f.is_fd() || f.id() != kNmtId || f.len != 2) return false;
  const std::uint8_t c = f.data[0];
  if (c != 0x01 && c != 0x02 && c != 0x80 && c != 0x81) return false;
  cmd = static_cast<NmtCommand>(c);
  node = f.data[1];
  return node <= 0x7F;
}

CanFrame encode_sync(std::uint8_t counter) noexcept {
  const std::uint8_t b[1] = {counter};
  return CanFrame::classic(kSyncId, b);
}

bool decode_sync(const CanFrame& f, std::uint8_t& counter) noexcept {
  if (f.is_error() || f.is_extended() || f.is_fd() || f.id() != kSyncId || f.len != 1) return false;
  counter = f.data[0];
  return counter >= 1 && counter <= kSyncCounterMax;
}

CanFrame encode_heartbeat(std::uint8_t node, NmtState s) noexcept {
  const std::uint8_t b[1] = {static_cast<std::uint8_t>(s)};
  return CanFrame::classic(kHeartbeatBase + node, b);
}

bool decode_heartbeat(const CanFrame& f, std::uint8_t& node, NmtState& s) noexcept {
  if (f.is_error() || f.is_extended() || f.is_fd() || f.len != 1) return false;
  if (f.id() <= kHeartbeatBase || f.id() > kHeartbeatBase + 0x7F) return false;
  const std::uint8_t v = f.data[0];
  if (!is_nmt_state(v)) return false;
  node = static_cast<std::uint8_t>(f.id() - kHeartbeatBase);
  s = static_cast<NmtState>(v);
  return true;
}

CanFrame encode_emcy(const Emcy& e) noexcept {
  std::uint8_t b[8];
  wire::put_u16(b, e.code);
  b[2] = e.error_register;
  b[3] = e.detail;
  wire::put_u32(b + 4, e.device_time_us);
  return CanFrame::classic(kEmcyBase + e.node, b);
}

bool decode_emcy(const CanFrame& f, Emcy& e) noexcept {
  if (f.is_error() || f.is_extended() || f.is_fd() || f.len != 8) return false;
  if (f.id() <= kEmcyBase || f.id() > kEmcyBase + 0x7F) return false;
  e.node = static_cast<std::uint8_t>(f.id() - kEmcyBase);
  e.code = wire::get_u16(f.data);
  e.error_register = f.data[2];
  e.detail = f.data[3];
  e.device_time_us = wire::get_u32(f.data + 4);
  return true;
}

}  // namespace crease::drivers::canopen
