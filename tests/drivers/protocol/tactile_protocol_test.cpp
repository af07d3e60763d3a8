#include "drivers/protocol/tactile_protocol.h"

#include <doctest/doctest.h>

#include <vector>

using namespace crease::drivers;

TEST_CASE("a tactile sample survives encoding, serial framing and decoding") {
  tactile::Sample s;
  s.device_time_us = 777;
  s.sample_counter = 65535;
  s.valid = 0x1F;
  for (int f = 0; f < tactile::kFingertips; ++f)
    for (int t = 0; t < tactile::kTaxels; ++t) s.pressure_kpa[f][t] = 0.5f * static_cast<float>(f * 40 + t);
  std::uint8_t payload[tactile::kSampleLen];
  REQUIRE(tactile::encode_sample(s, payload) == tactile::kSampleLen);
  std::vector<std::uint8_t> w(kSerialMaxWire);
  w.resize(serial_encode(0, tactile::kTypeSample, payload, w));
  SerialDeframer d;
  SerialFrame fr;
  bool got = false;
  for (auto b : w) got = d.push(b, fr) || got;
  REQUIRE(got);
  tactile::Sample o;
  REQUIRE(tactile::decode_sample(fr, o) == Decode::ok);
  CHECK(o.device_time_us == 777);
  CHECK(o.sample_counter == 65535);
  CHECK(o.pressure_kpa[4][33] == doctest::Approx(0.5 * (4 * 40 + 33)));
  fr.len = 20;
  CHECK(tactile::decode_sample(fr, o) == Decode::bad_format);
  fr.type = tactile::kTypeStart;
  CHECK(tactile::decode_sample(fr, o) == Decode::not_mine);
  std::uint16_t rate = 0;
  fr.len = static_cast<std::uint16_t>(tactile::encode_start(500, {fr.payload, 8}));
  REQUIRE(tactile::decode_start(fr, rate) == Decode::ok);
  CHECK(rate == 500);
}
