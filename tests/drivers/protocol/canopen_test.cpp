#include "drivers/protocol/canopen.h"

#include <doctest/doctest.h>

using namespace crease::drivers;
using namespace crease::drivers::canopen;

TEST_CASE("NMT, SYNC, heartbeat and EMCY round-trip and reject foreign frames") {
  NmtCommand c{};
  std::uint8_t node = 0;
  REQUIRE(decode_nmt(encode_nmt(NmtCommand::start, 5), c, node));
  CHECK(c == NmtCommand::start);
  CHECK(node == 5);
  CanFrame bad = encode_nmt(NmtCommand::start, 5);
  bad.data[0] = 0x33;
  CHECK_FALSE(decode_nmt(bad, c, node));

  std::uint8_t counter = 0;
  REQUIRE(decode_sync(encode_sync(240), counter));
  CHECK(counter == 240);
  CHECK_FALSE(decode_sync(encode_sync(0), counter));
  CHECK(next_sync_counter(240) == 1);
  CHECK(next_sync_counter(1) == 2);

  NmtState s{};
  REQUIRE(decode_heartbeat(encode_heartbeat(kHostNode, NmtState::operational), node, s));
  CHECK(node == kHostNode);
  CHECK(s == NmtState::operational);
  CHECK(encode_heartbeat(kHostNode, NmtState::operational).id() == 0x77F);
  CHECK_FALSE(decode_heartbeat(encode_sync(3), node, s));

  Emcy e{9, kEmcyHostTimeout, 0x11, 3, 123456};
  Emcy d;
  REQUIRE(decode_emcy(encode_emcy(e), d));
  CHECK(d.node == 9);
  CHECK(d.code == kEmcyHostTimeout);
  CHECK(d.error_register == 0x11);
  CHECK(d.device_time_us == 123456);
  CHECK_FALSE(decode_emcy(encode_sync(1), d));  // SYNC shares 0x080 but is not an EMCY
}
