// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78, init and final xor 0xFFFFFFFF), as
// iSCSI, ext4 and SSE4.2's crc32 instruction compute it. crc32c("123456789") == 0xE3069283.
#pragma once

#include <cstdint>
#include <span>

namespace crease::drivers {

// RT-safe. Uses SSE4.2's crc32 instruction where the CPU has it, else a table.
[[nodiscard]] std::uint32_t crc32c(std::span<const std::uint8_t> bytes) noexcept;
// Continues a CRC: crc32c_update(crc32c(a), b) == crc32c(a ++ b).
[[nodiscard]] std::uint32_t crc32c_update(std::uint32_t crc, std::span<const std::uint8_t> bytes) noexcept;
// The table path alone (tests compare it with the instruction path).
[[nodiscard]] std::uint32_t crc32c_update_portable(std::uint32_t crc, std::span<const std::uint8_t> bytes) noexcept;

}  // namespace crease::drivers
