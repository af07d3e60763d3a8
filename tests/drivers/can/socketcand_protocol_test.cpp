#include "drivers/can/socketcand_protocol.h"

#include <doctest/doctest.h>

#include <string>
#include <vector>

using namespace crease::drivers;
using namespace crease::drivers::socketcand;

TEST_CASE("client messages parse as python-can and socketcand send them") {
  Message m;
  REQUIRE(parse_message("< open can0 >", m));
  CHECK(m.command == Command::open);
  CHECK(std::string(m.interface) == "can0");
  REQUIRE(parse_message("< rawmode >", m));
  CHECK(m.command == Command::rawmode);
  REQUIRE(parse_message("< send 123 3 1 a ff >", m));  // python-can: no zero padding
  CHECK(m.command == Command::send);
  CHECK(m.frame.can_id == 0x123);
  CHECK(m.frame.len == 3);
  CHECK(m.frame.data[1] == 0x0A);
  CHECK(m.frame.data[2] == 0xFF);
  REQUIRE(parse_message("< send 1ABCDEF 0 >", m));
  CHECK(m.frame.is_extended());
  CHECK(m.frame.id() == 0x1ABCDEF);
  REQUIRE(parse_message("< send 800 1 00 >", m));
  CHECK(m.frame.is_extended());  // > 11 bits
  for (const char* bad : {"< send 123 9 1 2 3 4 5 6 7 8 9 >", "< send 123 2 1 >", "< send 123 1 1 2 >",
                          "< send xyz 0 >", "< send 123 1 100 >", "send 123 0", "< open >", "<>",
                          "< send 3FFFFFFFF 0 >"}) {
    CHECK_MESSAGE(!parse_message(bad, m), bad);
  }
  REQUIRE(parse_message("< bogus >", m));
  CHECK(m.command == Command::unknown);
}

TEST_CASE("frames format as socketcand sends them") {
  const std::uint8_t b[3] = {0x01, 0xAB, 0x00};
  char buf[128];
  const std::size_t n = format_frame(CanFrame::classic(0x12, b), 5'000'123'456, buf, sizeof(buf));
  CHECK(std::string(buf, n) == " < frame 012 5.000123 01AB00 >");
  const std::size_t e = format_frame(CanFrame::classic(0x1234567 | CAN_EFF_FLAG, {}), 0, buf, sizeof(buf));
  CHECK(std::string(buf, e) == " < frame 01234567 0.000000  >");
  CHECK(format_frame(CanFrame::fd(0x12, b), 0, buf, sizeof(buf)) == 0);
}

TEST_CASE("the stream splitter finds messages across reads and drops oversized ones") {
  StreamSplitter s;
  const std::string stream = "junk< hi >< open can0 >  < rawm";
  const char* msg;
  std::size_t len;
  std::size_t off = 0;
  std::vector<std::string> got;
  while (off < stream.size()) {
    off += s.feed(stream.data() + off, stream.size() - off, &msg, &len);
    if (msg) got.emplace_back(msg, len);
  }
  const std::string rest = "ode >";
  s.feed(rest.data(), rest.size(), &msg, &len);
  REQUIRE(msg);
  got.emplace_back(msg, len);
  REQUIRE(got.size() == 3);
  CHECK(got[0] == "< hi >");
  CHECK(got[2] == "< rawmode >");
  const std::string big = "<" + std::string(400, 'x') + "><echo>";
  off = 0;
  got.clear();
  while (off < big.size()) {
    off += s.feed(big.data() + off, big.size() - off, &msg, &len);
    if (msg) got.emplace_back(msg, len);
  }
  REQUIRE(got.size() == 1);
  CHECK(got[0] == "<echo>");
  CHECK(s.dropped() == 1);
}
