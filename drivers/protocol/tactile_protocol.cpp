#include "drivers/protocol/tactile_protocol.h"

#include "drivers/protocol/wire.h"

namespace crease::drivers::tactile {
using namespace wire;

std::size_t encode_sample(const Sample& s, std::span<std::uint8_t> out) noexcept {
  if (out.size() < kSampleLen) return 0;
  std::uint8_t* b = out.data();
  put_u32(b, s.device_time_us);
  put_u16(b + 4, s.sample_counter);
  b[6] = static_cast<std::uint8_t>(s.valid & 0x1F);
  b[7] = kTaxels;
  for (int f = 0; f < kFingertips; ++f)
    for (int t = 0; t < kTaxels; ++t)
      put_u16(b + 8 + 2 * (f * kTaxels + t), to_fixed<std::uint16_t>(s.pressure_kpa[f][t], kPressureUnitKpa));
  return kSampleLen;
}

Decode decode_sample(const SerialFrame& fr, Sample& out) noexcept {
  if (fr.type != kTypeSample) return Decode::not_mine;
  if (fr.len != kSampleLen || fr.payload[7] != kTaxels) return Decode::bad_format;
  const std::uint8_t* b = fr.payload;
  out.device_time_us = get_u32(b);
  out.sample_counter = get_u16(b + 4);
  out.valid = b[6] & 0x1F;
  for (int f = 0; f < kFingertips; ++f)
    for (int t = 0; t < kTaxels; ++t)
      out.pressure_kpa[f][t] = static_cast<float>(get_u16(b + 8 + 2 * (f * kTaxels + t)) * kPressureUnitKpa);
  return Decode::ok;
}

std::size_t encode_start(std::uint16_t rate_hz, std::span<std::uint8_t> out) noexcept {
  if (out.size() < 2) return 0;
  put_u16(out.data(), rate_hz);
  return 2;
}

Decode decode_start(const SerialFrame& f, std::uint16_t& rate_hz) noexcept {
  if (f.type != kTypeStart) return Decode::not_mine;
  if (f.len != 2) return Decode::bad_format;
  rate_hz = get_u16(f.payload);
  return rate_hz == 0 ? Decode::bad_format : Decode::ok;
}

}  // namespace crease::drivers::tactile
