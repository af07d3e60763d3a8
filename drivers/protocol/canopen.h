// The CANopen-flavoured services every Crease CAN device speaks (drivers/README.md):
// NMT (0x000), SYNC with counter (0x080), EMCY (0x080 + node), heartbeat (0x700 + node).
// 11-bit identifiers, classic frames. All functions are RT-safe.
#pragma once

#include <cstdint>

#include "drivers/can/can_frame.h"

namespace crease::drivers::canopen {

inline constexpr std::uint32_t kNmtId = 0x000;
inline constexpr std::uint32_t kSyncId = 0x080;
inline constexpr std::uint32_t kEmcyBase = 0x080;
inline constexpr std::uint32_t kTpdo1Base = 0x180;  // status
inline constexpr std::uint32_t kRpdo1Base = 0x200;  // command
inline constexpr std::uint32_t kTpdo2Base = 0x280;  // second status (pressure sensors)
inline constexpr std::uint32_t kRpdo2Base = 0x300;  // second command (stiffness)
inline constexpr std::uint32_t kHeartbeatBase = 0x700;
inline constexpr std::uint8_t kHostNode = 0x7F;     // the controller's own heartbeat: 0x77F
inline constexpr std::uint8_t kSyncCounterMax = 240;  // counter runs 1..240 (CiA 301)

enum class NmtCommand : std::uint8_t { start = 0x01, stop = 0x02, pre_operational = 0x80, reset_node = 0x81 };
enum class NmtState : std::uint8_t { boot_up = 0x00, stopped = 0x04, operational = 0x05, pre_operational = 0x7F };
// True when the byte is one of the NmtState values above.
[[nodiscard]] constexpr bool is_nmt_state(std::uint8_t v) noexcept {
  return v == 0x00 || v == 0x04 || v == 0x05 || v == 0x7F;
}

// Emergency error codes used by Crease devices (CiA 301 classes).
enum EmcyCode : std::uint16_t {
  kEmcyReset = 0x0000,          // error reset / no error
  kEmcyHostTimeout = 0x8130,    // command watchdog or host heartbeat expired
  kEmcyCrcErrors = 0x8110,      // too many command frames with a bad CRC
  kEmcyOverTemperature = 0x4210,
  kEmcyJointFault = 0xFF01,     // manufacturer specific: a joint reports a fault
};

struct Emcy {
  std::uint8_t node = 0;
  std::uint16_t code = 0;
  std::uint8_t error_register = 0;  // CiA 301 object 0x1001
  std::uint8_t detail = 0;
  std::uint32_t device_time_us = 0;
};

[[nodiscard]] CanFrame encode_nmt(NmtCommand cmd, std::uint8_t node) noexcept;  // node 0 = all
[[nodiscard]] bool decode_nmt(const CanFrame& f, NmtCommand& cmd, std::uint8_t& node) noexcept;
[[nodiscard]] CanFrame encode_sync(std::uint8_t counter) noexcept;
[[nodiscard]] bool decode_sync(const CanFrame& f, std::uint8_t& counter) noexcept;
[[nodiscard]] CanFrame encode_heartbeat(std::uint8_t node, NmtState s) noexcept;
[[nodiscard]] bool decode_heartbeat(const CanFrame& f, std::uint8_t& node, NmtState& s) noexcept;
[[nodiscard]] CanFrame encode_emcy(const Emcy& e) noexcept;
[[nodiscard]] bool decode_emcy(const CanFrame& f, Emcy& e) noexcept;
// Next SYNC counter after c (1..240, wrapping).
[[nodiscard]] constexpr std::uint8_t next_sync_counter(std::uint8_t c) noexcept {
  return c >= kSyncCounterMax ? 1 : static_cast<std::uint8_t>(c + 1);
}

}  // namespace crease::drivers::canopen
