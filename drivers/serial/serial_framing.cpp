#include "drivers/serial/serial_framing.h"

#include <cstring>

#include "drivers/serial/crc32c.h"

namespace crease::drivers {

std::size_t serial_encode(std::uint8_t seq, std::uint8_t type, std::span<const std::uint8_t> payload,
                          std::span<std::uint8_t> out) noexcept {
  if (payload.size() > kSerialMaxPayload) return 0;
  std::uint8_t body[kSerialMaxBody];
  const std::size_t len = payload.size();
  body[0] = seq;
  body[1] = type;
  body[2] = static_cast<std::uint8_t>(len & 0xFF);
  body[3] = static_cast<std::uint8_t>(len >> 8);
  if (len) std::memcpy(body + kSerialHeader, payload.data(), len);
  const std::uint32_t crc = crc32c({body, kSerialHeader + len});
  for (int k = 0; k < 4; ++k) body[kSerialHeader + len + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(crc >> (8 * k));
  const std::size_t body_len = kSerialHeader + len + 4;
  if (out.size() < cobs_max_encoded(body_len) + 2) return 0;
  out[0] = 0;  // leading delimiter: ends any garbage the receiver saw before this frame
  const std::size_t n = cobs_encode({body, body_len}, out.subspan(1));
  if (n == 0) return 0;
  out[n + 1] = 0;
  return n + 2;
}

void SerialDeframer::reset() noexcept {
  n_ = 0;
  discarding_ = false;
  have_seq_ = false;
}

bool SerialDeframer::push(std::uint8_t byte, SerialFrame& out) noexcept {
  if (byte != 0) {
    take_run(&byte, 1);
    return false;
  }
  return end_run(out);
}

void SerialDeframer::take_run(const std::uint8_t* p, std::size_t k) noexcept {
  if (discarding_) {
    stats_.bytes_discarded += k;
    return;
  }
  const std::size_t room = sizeof(buf_) - n_;
  if (k <= room) {
    std::memcpy(buf_ + n_, p, k);
    n_ += k;
    return;
  }
  // One byte past a full buffer: the run is over-long; it and the rest of it are discarded.
  ++stats_.overlong;
  stats_.bytes_discarded += sizeof(buf_) + 1 + (k - room - 1);
  n_ = 0;
  discarding_ = true;
}

bool SerialDeframer::end_run(SerialFrame& out) noexcept {
  // Delimiter: a frame ends here (or an empty run, or the end of a discarded run).
  const std::size_t n = n_;
  n_ = 0;
  if (discarding_) {
    discarding_ = false;
    return false;
  }
  if (n == 0) return false;
  // COBS adds at least one byte: a run shorter than the smallest frame's encoding (header and
  // CRC, no payload) cannot be a frame, and is refused without decoding it.
  if (n < kSerialHeader + 4 + 1) {
    ++stats_.cobs_errors;
    stats_.bytes_discarded += n;
    return false;
  }
  std::uint8_t body[kSerialMaxBody];
  const long m = cobs_decode({buf_, n}, body);
  if (m < static_cast<long>(kSerialHeader + 4)) {
    ++stats_.cobs_errors;
    stats_.bytes_discarded += n;
    return false;
  }
  const std::size_t len = static_cast<std::size_t>(body[2]) | static_cast<std::size_t>(body[3]) << 8;
  if (len > kSerialMaxPayload || kSerialHeader + len + 4 != static_cast<std::size_t>(m)) {
    ++stats_.cobs_errors;
    stats_.bytes_discarded += n;
    return false;
  }
  std::uint32_t crc = 0;
  for (int k = 0; k < 4; ++k) crc |= static_cast<std::uint32_t>(body[kSerialHeader + len + static_cast<std::size_t>(k)]) << (8 * k);
  if (crc32c({body, kSerialHeader + len}) != crc) {
    ++stats_.crc_errors;
    stats_.bytes_discarded += n;
    return false;
  }
  out.seq = body[0];
  out.type = body[1];
  out.len = static_cast<std::uint16_t>(len);
  if (len) std::memcpy(out.payload, body + kSerialHeader, len);
  if (have_seq_ && out.seq != static_cast<std::uint8_t>(last_seq_ + 1)) ++stats_.seq_gaps;
  have_seq_ = true;
  last_seq_ = out.seq;
  ++stats_.frames;
  return true;
}

std::size_t SerialDeframer::feed(std::span<const std::uint8_t> bytes, SerialFrame& out, bool* got) noexcept {
  // Run by run (memchr finds the delimiters), not byte by byte: the same result as push()
  // on every byte, at a fraction of the work per byte.
  *got = false;
  const std::uint8_t* const begin = bytes.data();
  const std::uint8_t* const end = begin + bytes.size();
  for (const std::uint8_t* p = begin; p < end;) {
    const auto* zero = static_cast<const std::uint8_t*>(std::memchr(p, 0, static_cast<std::size_t>(end - p)));
    if (!zero) {
      take_run(p, static_cast<std::size_t>(end - p));
      break;
    }
    if (zero > p) take_run(p, static_cast<std::size_t>(zero - p));
    p = zero + 1;
    if (end_run(out)) {
      *got = true;
      return static_cast<std::size_t>(p - begin);
    }
  }
  return bytes.size();
}

}  // namespace crease::drivers
