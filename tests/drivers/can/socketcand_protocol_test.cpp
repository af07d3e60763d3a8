#include "drivers/can/socketcand_protocol.h"

#include <doctest/doctest.h>

#include <random>
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

namespace {
// The splitter's contract byte by byte: a message starts at '<', ends at the next '>', and is
// dropped if it has more than kMaxMessage characters.
std::vector<std::string> split_by_byte(const std::string& s, std::uint64_t* dropped) {
  std::vector<std::string> out;
  bool in = false;
  std::string cur;
  for (char c : s) {
    if (!in) {
      if (c == '<') {
        in = true;
        cur = "<";
      }
      continue;
    }
    cur += c;
    if (c == '>') {
      in = false;
      if (cur.size() > kMaxMessage) {
        ++*dropped;
      } else {
        out.push_back(cur);
      }
    }
  }
  return out;
}
}  // namespace

TEST_CASE("the splitter, fed in any chunks, finds the messages its byte-by-byte contract finds") {
  std::mt19937 rng(3);
  const char alphabet[] = "<<>> abc01x";
  for (int trial = 0; trial < 300; ++trial) {
    std::string s;
    for (int part = 0; part < 20; ++part) {
      if (rng() % 6 == 0) {
        s += "<" + std::string(kMaxMessage - 3 + rng() % 5, 'y') + ">";  // at the size limit
      } else {
        for (unsigned k = rng() % 20; k > 0; --k) s += alphabet[rng() % (sizeof(alphabet) - 1)];
      }
    }
    std::uint64_t dropped = 0;
    const auto want = split_by_byte(s, &dropped);
    StreamSplitter sp;
    std::vector<std::string> got;
    for (std::size_t off = 0; off < s.size();) {
      const std::size_t chunk = std::min<std::size_t>(s.size() - off, 1 + rng() % 64);
      for (std::size_t done = 0; done < chunk;) {
        const char* msg;
        std::size_t len;
        done += sp.feed(s.data() + off + done, chunk - done, &msg, &len);
        if (msg) got.emplace_back(msg, len);
      }
      off += chunk;
    }
    REQUIRE(got == want);
    CHECK(sp.dropped() == dropped);
  }
}

TEST_CASE("a text longer than any message does not parse") {
  Message m;
  CHECK(parse_message("< echo" + std::string(kMaxMessage - 8, ' ') + ">", m));  // kMaxMessage - 1 characters
  CHECK_FALSE(parse_message("< echo" + std::string(kMaxMessage, ' ') + ">", m));
}

TEST_CASE("whitespace is space, tab, CR and LF, and no other byte") {
  // The tokenizer classifies bytes by table: every byte value, as a separator and at the ends.
  Message m;
  for (int b = 0; b < 256; ++b) {
    const char c = static_cast<char>(b);
    const bool space = c == ' ' || c == '\t' || c == '\r' || c == '\n';
    const std::string sep = std::string("< send") + c + "123 1" + c + "ff" + c + ">";
    CHECK_MESSAGE((parse_message(sep, m) && m.command == Command::send) == space, b);
    REQUIRE(parse_message(std::string("<echo") + c + ">", m));
    CHECK_MESSAGE((m.command == Command::echo) == space, b);
    CHECK_MESSAGE(parse_message(std::string(1, c) + "< echo >" + c, m) == space, b);
  }
}
