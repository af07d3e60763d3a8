#include "drivers/serial/serial_framing.h"

#include <doctest/doctest.h>

#include <random>
#include <vector>

#include "drivers/serial/cobs.h"
#include "drivers/serial/crc32c.h"
#include "rt/alloc_guard.h"

using namespace crease::drivers;
using Bytes = std::vector<std::uint8_t>;

TEST_CASE("CRC-32C check value") {
  const Bytes s = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  CHECK(crc32c(s) == 0xE3069283u);
  CHECK(crc32c_update(crc32c({s.data(), 4}), {s.data() + 4, 5}) == 0xE3069283u);
  CHECK(crc32c_update_portable(0, s) == 0xE3069283u);
}

TEST_CASE("CRC-32C: the instruction path (where the CPU has one) equals the table path") {
  std::mt19937 rng(7);
  Bytes b(300);
  for (auto& x : b) x = static_cast<std::uint8_t>(rng());
  for (std::size_t len = 0; len <= b.size(); len += 1 + len / 8) {
    for (std::size_t off = 0; off < 3; ++off) {
      const std::span<const std::uint8_t> s{b.data() + off, len - (len >= off ? off : len)};
      CHECK(crc32c_update(0x1234567u, s) == crc32c_update_portable(0x1234567u, s));
    }
  }
}

TEST_CASE("COBS known vectors and round trips") {
  auto enc = [](const Bytes& in) {
    Bytes out(cobs_max_encoded(in.size()));
    out.resize(cobs_encode(in, out));
    return out;
  };
  CHECK(enc({0x00}) == Bytes{0x01, 0x01});
  CHECK(enc({0x00, 0x00}) == Bytes{0x01, 0x01, 0x01});
  CHECK(enc({0x11, 0x22, 0x00, 0x33}) == Bytes{0x03, 0x11, 0x22, 0x02, 0x33});
  CHECK(enc({0x11, 0x00, 0x00, 0x00}) == Bytes{0x02, 0x11, 0x01, 0x01, 0x01});
  Bytes run254(254);
  for (std::size_t i = 0; i < run254.size(); ++i) run254[i] = static_cast<std::uint8_t>(i + 1);
  const Bytes e254 = enc(run254);
  CHECK(e254.size() == 256);
  CHECK(e254[0] == 0xFF);
  std::mt19937 rng(7);
  for (int t = 0; t < 500; ++t) {
    Bytes in(rng() % 700);
    for (auto& b : in) b = static_cast<std::uint8_t>(rng() % 4 == 0 ? 0 : rng());
    const Bytes e = enc(in);
    for (auto b : e) REQUIRE(b != 0);
    Bytes out(in.size() + 1);
    const long n = cobs_decode(e, out);
    REQUIRE(n == static_cast<long>(in.size()));
    out.resize(static_cast<std::size_t>(n));
    CHECK(out == in);
  }
  Bytes out(16);
  CHECK(cobs_decode(Bytes{0x05, 0x11}, out) == -1);        // code runs past the end
  CHECK(cobs_decode(Bytes{0x03, 0x11, 0x00}, out) == -1);  // zero inside
}

namespace {
Bytes wire(std::uint8_t seq, std::uint8_t type, const Bytes& payload) {
  Bytes w(kSerialMaxWire);
  w.resize(serial_encode(seq, type, payload, w));
  return w;
}
}  // namespace

TEST_CASE("frames decode; garbage costs at most the frame it hits; corruption is never accepted") {
  std::mt19937 rng(11);
  SerialDeframer d;
  SerialFrame f;
  std::vector<Bytes> sent;
  Bytes stream;
  for (int i = 0; i < 300; ++i) {
    Bytes p(rng() % 200);
    for (auto& b : p) b = static_cast<std::uint8_t>(rng());
    const Bytes w = wire(static_cast<std::uint8_t>(i), 3, p);
    sent.push_back(p);
    if (i % 10 == 5) {  // garbage between frames (may include zeros)
      for (int k = 0; k < 37; ++k) stream.push_back(static_cast<std::uint8_t>(rng() % 3 == 0 ? 0 : rng()));
    }
    stream.insert(stream.end(), w.begin(), w.end());
  }
  int got = 0;
  for (std::uint8_t b : stream) {
    if (d.push(b, f)) {
      REQUIRE(got < 300);
      CHECK(f.seq == static_cast<std::uint8_t>(got));
      CHECK(Bytes(f.payload, f.payload + f.len) == sent[static_cast<std::size_t>(got)]);
      ++got;
    }
  }
  CHECK(got == 300);  // garbage between frames never costs a valid frame
  CHECK(d.stats().seq_gaps == 0);

  // Bit flips inside frames: the damaged frame is dropped, its successor is accepted.
  SerialDeframer d2;
  int accepted = 0, damaged = 0;
  for (int i = 0; i < 400; ++i) {
    Bytes p(8 + rng() % 100);
    for (auto& b : p) b = static_cast<std::uint8_t>(rng());
    Bytes w = wire(static_cast<std::uint8_t>(i), 1, p);
    const bool flip = i % 3 == 1;
    if (flip) {
      const std::size_t at = rng() % (w.size() - 1);
      w[at] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
      ++damaged;
    }
    bool this_one = false;
    for (std::uint8_t b : w) {
      if (d2.push(b, f)) {
        CHECK(Bytes(f.payload, f.payload + f.len) == p);  // never a corrupted payload
        this_one = true;
      }
    }
    if (!flip) CHECK(this_one);  // resynchronised within one frame
    accepted += this_one ? 1 : 0;
  }
  CHECK(accepted >= 400 - damaged);
  CHECK(d2.stats().crc_errors + d2.stats().cobs_errors > 0);
}

TEST_CASE("an over-long run is discarded up to the next delimiter") {
  SerialDeframer d;
  SerialFrame f;
  for (std::size_t i = 0; i < 3 * kSerialMaxWire; ++i) CHECK_FALSE(d.push(0x55, f));
  const Bytes w = wire(9, 2, {1, 2, 3});
  int got = 0;
  for (std::uint8_t b : w) got += d.push(b, f) ? 1 : 0;
  CHECK(got == 1);  // the frame's leading delimiter ends the discarded run
  CHECK(d.stats().overlong == 1);
  Bytes big(kSerialMaxPayload + 1);
  Bytes out(kSerialMaxWire);
  CHECK(serial_encode(0, 0, big, out) == 0);
}

TEST_CASE("deframing does not allocate") {
  SerialDeframer d;
  SerialFrame f;
  const Bytes w = wire(1, 1, Bytes(300, 0xAB));
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark mark;
    for (int i = 0; i < 10; ++i)
      for (std::uint8_t b : w) (void)d.push(b, f);
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(d.stats().frames == 10);
}

TEST_CASE("feed (run by run) gives what push gives on every byte: frames, consumed counts and stats") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    // A stream of valid frames, garbage, bare delimiters, corrupted frames and over-long runs.
    Bytes s;
    for (int part = 0; part < 12; ++part) {
      switch (rng() % 5) {
        case 0: {
          Bytes payload(rng() % 40);
          for (auto& b : payload) b = static_cast<std::uint8_t>(rng());
          const Bytes w = wire(static_cast<std::uint8_t>(part), 1, payload);
          s.insert(s.end(), w.begin(), w.end());
          break;
        }
        case 1:
          for (unsigned k = rng() % 30; k > 0; --k) s.push_back(static_cast<std::uint8_t>(rng()));
          break;
        case 2: s.insert(s.end(), rng() % 3 + 1, 0); break;
        case 3: {
          Bytes w = wire(1, 2, {4, 5, 6, 7});
          w[2 + rng() % (w.size() - 4)] ^= static_cast<std::uint8_t>(1 + rng() % 255);
          s.insert(s.end(), w.begin(), w.end());
          break;
        }
        default: s.insert(s.end(), kSerialMaxWire - 2 + rng() % 5, 0x5A); break;  // at the edge of over-long
      }
    }
    SerialDeframer a, b;
    SerialFrame fa, fb;
    std::vector<std::pair<std::size_t, Bytes>> by_byte, by_feed;  // (stream offset after, payload)
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (a.push(s[i], fa)) by_byte.emplace_back(i + 1, Bytes(fa.payload, fa.payload + fa.len));
    }
    for (std::size_t off = 0; off < s.size();) {
      const std::size_t chunk = std::min<std::size_t>(s.size() - off, 1 + rng() % 700);
      std::size_t done = 0;
      while (done < chunk) {
        bool got = false;
        done += b.feed({s.data() + off + done, chunk - done}, fb, &got);
        if (got) by_feed.emplace_back(off + done, Bytes(fb.payload, fb.payload + fb.len));
      }
      off += chunk;
    }
    REQUIRE(by_feed == by_byte);
    const auto &x = a.stats(), &y = b.stats();
    CHECK(x.frames == y.frames);
    CHECK(x.crc_errors == y.crc_errors);
    CHECK(x.cobs_errors == y.cobs_errors);
    CHECK(x.overlong == y.overlong);
    CHECK(x.seq_gaps == y.seq_gaps);
    CHECK(x.bytes_discarded == y.bytes_discarded);
  }
}

namespace {
// COBS decoding byte by byte (the reference the block-wise cobs_decode must equal).
long cobs_decode_by_byte(const Bytes& in, std::size_t cap, Bytes& out) {
  out.clear();
  std::size_t i = 0;
  while (i < in.size()) {
    const std::uint8_t code = in[i++];
    if (code == 0) return -1;
    for (std::uint8_t k = 1; k < code; ++k) {
      if (i >= in.size() || in[i] == 0 || out.size() >= cap) return -1;
      out.push_back(in[i++]);
    }
    if (code != 0xFF && i < in.size()) {
      if (out.size() >= cap) return -1;
      out.push_back(0);
    }
  }
  return static_cast<long>(out.size());
}
}  // namespace

TEST_CASE("cobs_decode equals the byte-by-byte definition on valid, corrupted and random input") {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 3000; ++trial) {
    Bytes raw(rng() % 700);
    for (auto& b : raw) b = rng() % 4 == 0 ? 0 : static_cast<std::uint8_t>(rng());
    Bytes in(cobs_max_encoded(raw.size()));
    in.resize(cobs_encode(raw, in));
    switch (trial % 3) {
      case 0: break;                                                        // valid
      case 1: if (!in.empty()) in[rng() % in.size()] = static_cast<std::uint8_t>(rng()); break;  // one byte changed
      default: in = raw; break;                                             // not COBS at all
    }
    const std::size_t cap = rng() % 2 ? 1024 : rng() % 700;
    Bytes want;
    const long n_want = cobs_decode_by_byte(in, cap, want);
    Bytes got(cap + 1);
    const long n_got = cobs_decode(in, {got.data(), cap});
    REQUIRE(n_got == n_want);
    if (n_got > 0) CHECK(std::equal(want.begin(), want.end(), got.begin()));
    if (trial % 3 == 0 && cap >= raw.size()) CHECK(n_got == static_cast<long>(raw.size()));
  }
}

namespace {
// COBS encoding byte by byte (the reference the block-wise cobs_encode must equal).
Bytes cobs_encode_by_byte(const Bytes& in) {
  Bytes out(1);
  std::size_t code_at = 0;
  std::uint8_t code = 1;
  for (std::uint8_t b : in) {
    if (b != 0) out.push_back(b);
    if (b == 0 || ++code == 0xFF) {
      out[code_at] = b == 0 ? code : 0xFF;
      code_at = out.size();
      out.push_back(0);
      code = 1;
    }
  }
  out[code_at] = code;
  return out;
}
}  // namespace

TEST_CASE("cobs_encode equals the byte-by-byte definition, at and around the 254-byte blocks") {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 3000; ++trial) {
    Bytes raw(trial < 600 ? static_cast<std::size_t>(trial) : rng() % 1100);
    const unsigned zero_one_in = 1 + rng() % 400;  // from mostly zeros to no zero at all
    for (auto& b : raw)
      b = rng() % zero_one_in == 0 ? 0 : static_cast<std::uint8_t>(1 + rng() % 255);
    const Bytes want = cobs_encode_by_byte(raw);
    Bytes got(cobs_max_encoded(raw.size()));
    REQUIRE(cobs_encode(raw, got) == want.size());
    got.resize(want.size());
    CHECK(got == want);
    CHECK(cobs_encode(raw, {got.data(), cobs_max_encoded(raw.size()) - 1}) == 0);  // no room
  }
}

TEST_CASE("a run shorter than the smallest frame is a COBS error, its bytes discarded") {
  SerialFrame f;
  for (std::size_t n = 1; n <= kSerialHeader + 4; ++n) {
    SerialDeframer d;
    Bytes run(n, 0x01);
    run.push_back(0);
    bool got = true;
    CHECK(d.feed(run, f, &got) == run.size());
    CHECK_FALSE(got);
    CHECK(d.stats().cobs_errors == 1);
    CHECK(d.stats().bytes_discarded == n);
  }
  // The smallest frame itself (empty payload) still deframes.
  SerialDeframer d;
  const Bytes w = wire(1, 2, {});
  bool got = false;
  for (std::size_t k = 0; k < w.size() && !got;) k += d.feed({w.data() + k, w.size() - k}, f, &got);
  CHECK(got);
  CHECK(f.len == 0);
}
