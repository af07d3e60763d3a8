// CanFrame: one classic CAN or CAN FD frame, byte-for-byte the layout of Linux's
// struct canfd_frame (linux/can.h). A classic frame is the first 16 bytes (struct can_frame:
// can_id, len = can_dlc, pad, res, len8_dlc, data[8]); an FD frame carries CANFD_FDF in flags.
#pragma once

#include <linux/can.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

namespace crease::drivers {

struct alignas(8) CanFrame {
  std::uint32_t can_id = 0;  // 11/29-bit id plus CAN_EFF_FLAG / CAN_RTR_FLAG / CAN_ERR_FLAG
  std::uint8_t len = 0;      // payload bytes: 0..8 classic, 0..64 FD (a valid FD length)
  std::uint8_t flags = 0;    // CANFD_BRS | CANFD_ESI | CANFD_FDF (FDF marks an FD frame)
  std::uint8_t res0 = 0;
  std::uint8_t res1 = 0;     // classic frames: len8_dlc (unused here, kept 0)
  std::uint8_t data[64] = {};

  static constexpr std::size_t kClassicMtu = CAN_MTU;  // 16
  static constexpr std::size_t kFdMtu = CANFD_MTU;     // 72

  [[nodiscard]] bool is_fd() const noexcept { return (flags & CANFD_FDF) != 0; }
  [[nodiscard]] bool is_extended() const noexcept { return (can_id & CAN_EFF_FLAG) != 0; }
  [[nodiscard]] bool is_error() const noexcept { return (can_id & CAN_ERR_FLAG) != 0; }
  [[nodiscard]] bool is_rtr() const noexcept { return (can_id & CAN_RTR_FLAG) != 0; }
  // The identifier without flag bits.
  [[nodiscard]] std::uint32_t id() const noexcept {
    return can_id & (is_extended() ? CAN_EFF_MASK : CAN_SFF_MASK);
  }
  // Bytes this frame occupies on a raw CAN socket (CAN_MTU or CANFD_MTU).
  [[nodiscard]] std::size_t mtu() const noexcept { return is_fd() ? kFdMtu : kClassicMtu; }
  [[nodiscard]] std::span<const std::uint8_t> payload() const noexcept { return {data, len}; }

  // A classic data frame; len is clamped to 8.
  static CanFrame classic(std::uint32_t can_id, std::span<const std::uint8_t> bytes) noexcept;
  // An FD data frame (BRS set); len is rounded up to the next valid FD length, padding 0.
  static CanFrame fd(std::uint32_t can_id, std::span<const std::uint8_t> bytes) noexcept;

  friend bool operator==(const CanFrame& a, const CanFrame& b) noexcept {
    return a.can_id == b.can_id && a.len == b.len && a.is_fd() == b.is_fd() &&
           std::memcmp(a.data, b.data, a.len) == 0;
  }
};

static_assert(sizeof(CanFrame) == sizeof(canfd_frame), "CanFrame must match struct canfd_frame");
static_assert(offsetof(CanFrame, len) == offsetof(canfd_frame, len));
static_assert(offsetof(CanFrame, flags) == offsetof(canfd_frame, flags));
static_assert(offsetof(CanFrame, data) == offsetof(canfd_frame, data));
static_assert(offsetof(CanFrame, data) == offsetof(can_frame, data));
static_assert(offsetof(CanFrame, len) == offsetof(can_frame, can_dlc));

// Valid CAN FD payload lengths are 0..8, 12, 16, 20, 24, 32, 48, 64.
[[nodiscard]] std::uint8_t can_fd_round_len(std::size_t n) noexcept;
[[nodiscard]] bool can_fd_valid_len(std::size_t n) noexcept;
// DLC code (0..15) of a payload length and back.
[[nodiscard]] std::uint8_t can_len_to_dlc(std::uint8_t len) noexcept;
[[nodiscard]] std::uint8_t can_dlc_to_len(std::uint8_t dlc) noexcept;

// Bits this frame occupies on the wire including stuff bits (worst case estimate) and
// interframe space, split into arbitration-rate bits and data-rate bits (FD with BRS).
struct CanFrameBits {
  std::uint32_t nominal_bits;
  std::uint32_t data_bits;
};
[[nodiscard]] CanFrameBits can_frame_bits(const CanFrame& f) noexcept;
// Wire time in ns at the given nominal and data bitrates (bit/s).
[[nodiscard]] std::int64_t can_frame_time_ns(const CanFrame& f, std::uint32_t nominal_bps,
                                             std::uint32_t data_bps) noexcept;

}  // namespace crease::drivers
