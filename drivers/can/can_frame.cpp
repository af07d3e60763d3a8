#include "drivers/can/can_frame.h"

#include <algorithm>

namespace crease::drivers {
namespace {
constexpr std::uint8_t kDlcToLen[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
}

std::uint8_t can_fd_round_len(std::size_t n) noexcept {
  for (std::uint8_t l : kDlcToLen) {
    if (l >= n) return l;
  }
  return 64;
}

bool can_fd_valid_len(std::size_t n) noexcept { return n <= 64 && can_fd_round_len(n) == n; }

std::uint8_t can_len_to_dlc(std::uint8_t len) noexcept {
  for (std::uint8_t d = 0; d < 16; ++d) {
    if (kDlcToLen[d] >= len) return d;
  }
  return 15;
}

std::uint8_t can_dlc_to_len(std::uint8_t dlc) noexcept { return kDlcToLen[dlc & 0x0F]; }

CanFrame CanFrame::classic(std::uint32_t can_id, std::span<const std::uint8_t> bytes) noexcept {
  CanFrame f;
  f.can_id = can_id;
  f.len = static_cast<std::uint8_t>(std::min<std::size_t>(bytes.size(), 8));
  if (f.len != 0) std::memcpy(f.data, bytes.data(), f.len);  // an empty span may hold nullptr
  return f;
}

CanFrame CanFrame::fd(std::uint32_t can_id, std::span<const std::uint8_t> bytes) noexcept {
  CanFrame f;
  f.can_id = can_id;
  f.flags = CANFD_FDF | CANFD_BRS;
  const std::size_t n = std::min<std::size_t>(bytes.size(), 64);
  if (n != 0) std::memcpy(f.data, bytes.data(), n);
  f.len = can_fd_round_len(n);
  return f;
}

CanFrameBits can_frame_bits(const CanFrame& f) noexcept {
  // Classic: SOF+id(11)+RTR+IDE+r0+DLC(4) = 19, ext adds 20; CRC 15+del, ACK 2, EOF 7, IFS 3.
  // Stuffing worst case adds one bit per 4 of the stuffed region (SOF..CRC).
  const std::uint32_t hdr = f.is_extended() ? 39u : 19u;
  if (!f.is_fd()) {
    const std::uint32_t stuffed = hdr + 8u * f.len + 15u;
    return {stuffed + (stuffed - 1) / 4 + 1 + 2 + 7 + 3, 0};
  }
  // FD: arbitration phase at the nominal rate (header up to BRS, ACK, EOF, IFS); data phase
  // (ESI, DLC, data, stuff count, CRC 17/21 + fixed stuff bits) at the data rate.
  const bool brs = (f.flags & CANFD_BRS) != 0;
  const std::uint32_t crc = f.len > 16 ? 21u : 17u;
  const std::uint32_t data_region = 1 + 4 + 8u * f.len + 4 + crc;
  const std::uint32_t data_bits = data_region + data_region / 4 + 1;  // stuffing + CRC delim
  const std::uint32_t nominal = hdr + 2 + 2 + 7 + 3 + hdr / 4;
  if (!brs) return {nominal + data_bits, 0};
  return {nominal, data_bits};
}

std::int64_t can_frame_time_ns(const CanFrame& f, std::uint32_t nominal_bps,
                               std::uint32_t data_bps) noexcept {
  const CanFrameBits b = can_frame_bits(f);
  const std::int64_t n = nominal_bps ? std::int64_t{b.nominal_bits} * 1'000'000'000 / nominal_bps : 0;
  const std::int64_t d = data_bps ? std::int64_t{b.data_bits} * 1'000'000'000 / data_bps : 0;
  return n + d;
}

}  // namespace crease::drivers
