// libFuzzer target: every CAN frame decoder (hand, arm, CANopen services, error frames).
// Input: [0] node (low 7 bits) | FD flag (bit 7), [1..4] can_id little-endian, [5..] payload.
// Invariant: decoding never crashes; a decoded frame re-encodes to a frame that decodes equal.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "drivers/can/can_bus.h"
#include "drivers/protocol/arm_protocol.h"
#include "drivers/protocol/canopen.h"
#include "drivers/protocol/hand_protocol.h"

using namespace crease::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 5) return 0;
  CanFrame f;
  const std::uint8_t node = data[0] & 0x7F;
  std::memcpy(&f.can_id, data + 1, 4);
  const std::size_t n = size - 5 > 64 ? 64 : size - 5;
  std::memcpy(f.data, data + 5, n);
  f.len = static_cast<std::uint8_t>(n);
  if (data[0] & 0x80) f.flags = CANFD_FDF | CANFD_BRS;
  hand::Command hc;
  if (hand::decode(node, f, hc) == Decode::ok) {
    hand::Command again;
    if (hand::decode(node, hand::encode(node, hc), again) != Decode::ok || again.seq != hc.seq) __builtin_trap();
  }
  hand::Stiffness hs;
  (void)hand::decode(node, f, hs);
  hand::Status st;
  if (hand::decode(node, f, st) == Decode::ok) {
    hand::Status again;
    if (hand::decode(node, hand::encode(node, st), again) != Decode::ok || again.cmd_seq != st.cmd_seq) __builtin_trap();
  }
  hand::Pressure hp;
  (void)hand::decode(node, f, hp);
  arm::Command ac;
  if (arm::decode(node, f, ac) == Decode::ok) {
    arm::Command again;
    if (arm::decode(node, arm::encode(node, ac), again) != Decode::ok || again.controlword != ac.controlword) __builtin_trap();
  }
  arm::Status as;
  (void)arm::decode(node, f, as);
  canopen::NmtCommand nc;
  std::uint8_t nn;
  (void)canopen::decode_nmt(f, nc, nn);
  std::uint8_t counter;
  (void)canopen::decode_sync(f, counter);
  canopen::NmtState ns;
  (void)canopen::decode_heartbeat(f, nn, ns);
  canopen::Emcy e;
  (void)canopen::decode_emcy(f, e);
  (void)bus_state_after_error_frame(BusState::error_active, f);
  return 0;
}
