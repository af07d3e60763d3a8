#include "drivers/can/candump_log.h"

#include <doctest/doctest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"

using namespace crease::drivers;

namespace {
std::string tmp_path(const char* name) {
  return "/tmp/crease_candump_" + std::to_string(::getpid()) + "_" + name;
}

std::vector<CandumpEntry> sample_entries() {
  std::vector<CandumpEntry> v;
  for (int i = 0; i < 40; ++i) {
    CandumpEntry e;
    e.timestamp_ns = 1'700'000'000'000'000'000 + std::int64_t{i} * 1'000'000;
    std::snprintf(e.interface, sizeof(e.interface), "vcan0");
    std::uint8_t b[8];
    for (int k = 0; k < 8; ++k) b[k] = static_cast<std::uint8_t>(i * 7 + k);
    const std::uint32_t id = (i % 3 == 0) ? (0x1ABCDE00u + static_cast<std::uint32_t>(i)) | CAN_EFF_FLAG
                                          : 0x100u + static_cast<std::uint32_t>(i);
    e.frame = CanFrame::classic(id, std::span<const std::uint8_t>(b, static_cast<std::size_t>(i % 9)));
    v.push_back(e);
  }
  return v;
}

std::string run(const std::string& cmd) {
  std::string out;
  if (FILE* p = ::popen(cmd.c_str(), "r")) {
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
    ::pclose(p);
  }
  return out;
}
}  // namespace

TEST_CASE("lines in can-utils' format parse and format back identically") {
  const char* lines[] = {
      "(1700000000.000123) can0 123#DEADBEEF",
      "(1700000000.100000) can1 1ABCDEF0#0102",
      "(0.000001) vcan0 7FF#",
      "(12.500000) can0 321#R",
      "(12.500001) can0 321#R4",
      "(1.000000) can0 042##1000102030405060708090A0B",
      "(1.000001) can0 20000004#0004000000000000",
  };
  for (const char* l : lines) {
    CandumpEntry e;
    REQUIRE_MESSAGE(parse_candump_line(l, e), l);
    char buf[256];
    const std::size_t n = format_candump_line(e, buf, sizeof(buf));
    CHECK(std::string(buf, n) == l);
  }
  CandumpEntry e;
  REQUIRE(parse_candump_line("(1.000000) can0 042##1000102030405060708090A0B\n", e));
  CHECK(e.frame.is_fd());
  CHECK(e.frame.len == 12);
  CHECK(e.frame.data[11] == 0x0B);
  CHECK(e.timestamp_ns == 1'000'000'000);
}

TEST_CASE("malformed lines are rejected") {
  const char* bad[] = {"", "(1.0 can0 123#00", "(1.000000) can0 12#00", "(1.000000) can0 123#0",
                       "(1.000000) can0 123#001122334455667788", "(1.000000) can0 800#00",
                       "(1.000000) can0 123##1001122334455667788", "(1.000000) can0 12G#00",
                       "(1.000000) can0 123#R9", "1.000000 can0 123#00"};
  for (const char* l : bad) {
    CandumpEntry e;
    CHECK_MESSAGE(!parse_candump_line(l, e), l);
  }
}

TEST_CASE("a written log reads back; a bad line names file and line") {
  const std::string path = tmp_path("rw.log");
  const auto entries = sample_entries();
  {
    CandumpWriter w(path);
    for (const auto& e : entries) w.write(e);
  }
  CandumpReader r(path);
  CandumpEntry e;
  std::size_t i = 0;
  while (r.next(e)) {
    REQUIRE(i < entries.size());
    CHECK(e.frame == entries[i].frame);
    CHECK(e.timestamp_ns == entries[i].timestamp_ns);
    ++i;
  }
  CHECK(i == entries.size());
  {
    std::ofstream f(path, std::ios::app);
    f << "garbage here\n";
  }
  CandumpReader r2(path);
  CHECK_THROWS_WITH_AS(
      [&] {
        while (r2.next(e)) {
        }
      }(),
      doctest::Contains("line 41"), std::runtime_error);
  std::remove(path.c_str());
}

TEST_CASE("python-can's CanutilsLogReader and can-utils' log2asc read our log") {
  const std::string path = tmp_path("ext.log");
  const auto entries = sample_entries();
  {
    CandumpWriter w(path);
    for (const auto& e : entries) w.write(e);
  }
  // python-can 4.1 (Debian python3-can): print id, extended flag and data of every message.
  const std::string py = run(
      "/usr/bin/python3 -c \"import can,sys\n"
      "for m in can.CanutilsLogReader(sys.argv[1]): print('%x %d %s' % (m.arbitration_id, "
      "m.is_extended_id, m.data.hex()))\" " + path + " 2>&1");
  std::ostringstream want;
  for (const auto& e : entries) {
    want << std::hex << e.frame.id() << ' ' << (e.frame.is_extended() ? 1 : 0) << ' ';
    for (std::uint8_t k = 0; k < e.frame.len; ++k) {
      char h[3];
      std::snprintf(h, sizeof(h), "%02x", e.frame.data[k]);
      want << h;
    }
    want << '\n';
  }
  CHECK(py == want.str());
  // log2asc: one ASC line per frame, ids in hex ("1ABCDE00x" for extended).
  const std::string asc = run("log2asc -I " + path + " vcan0 2>&1");
  int frame_lines = 0;
  std::istringstream in(asc);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find(" Rx ") != std::string::npos) ++frame_lines;
  }
  CHECK(frame_lines == static_cast<int>(entries.size()));
  CHECK(asc.find("1ABCDE00x") != std::string::npos);
  std::remove(path.c_str());
}

TEST_CASE("a log replays onto a mock bus in order") {
  const std::string path = tmp_path("replay.log");
  const auto entries = sample_entries();
  {
    CandumpWriter w(path);
    for (const auto& e : entries) w.write(e);
  }
  const std::string bus = "replay-" + std::to_string(::getpid());
  MockCanBroker broker({bus, 0, 0, false});
  MockCanBus tx({bus, 1, 0, 0}), rx({bus, 2, 0, 0});
  for (int i = 0; i < 200 && broker.connected_nodes() < 2; ++i) ::usleep(2000);
  CandumpReader r(path);
  CHECK(replay_candump(r, tx, 20.0) == entries.size());  // 40 ms of log at 20x
  std::size_t got = 0;
  RxFrame f;
  for (int spins = 0; spins < 2000 && got < entries.size(); ++spins) {
    if (rx.try_receive(f) == RecvResult::frame) {
      CHECK(f.frame == entries[got].frame);
      ++got;
    } else {
      ::usleep(500);
    }
  }
  CHECK(got == entries.size());
  std::remove(path.c_str());
}

namespace {
// A bus whose transmit queue stays full for a long stretch (a reader that holds the bus up):
// it refuses frame `stall_at` for `refusals` tries, far beyond any fixed retry budget.
class StallingBus final : public CanBus {
 public:
  StallingBus(std::size_t stall_at, std::uint64_t refusals, int fd) : stall_at_(stall_at), refusals_(refusals), fd_(fd) {}
  SendResult send(const CanFrame& f) noexcept override {
    if (sent.size() == stall_at_ && refused < refusals_) {
      ++refused;
      return SendResult::no_buffers;
    }
    sent.push_back(f);
    return SendResult::ok;
  }
  RecvResult try_receive(RxFrame&) noexcept override { return RecvResult::empty; }
  int fd() const noexcept override { return fd_; }
  BusState state() const noexcept override { return BusState::error_active; }
  void restart() noexcept override {}
  const CanBusCounters& counters() const noexcept override { return counters_; }
  int errno_value() const noexcept override { return ENOBUFS; }
  std::vector<CanFrame> sent;
  std::uint64_t refused = 0;

 private:
  std::size_t stall_at_;
  std::uint64_t refusals_;
  int fd_;
  CanBusCounters counters_;
};

std::uint64_t g_pauses = 0;
void count_pause(std::int64_t) { ++g_pauses; }  // the replay's pause, without the wait
}  // namespace

TEST_CASE("a replay waits out a full transmit queue however long it lasts, and stops when the bus is gone") {
  const std::string path = tmp_path("stall.log");
  const auto entries = sample_entries();
  {
    CandumpWriter w(path);
    for (const auto& e : entries) w.write(e);
  }
  int sv[2];
  REQUIRE(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv) == 0);
  // The old replay gave up after 100,001 refusals ("bus refused frame N (No buffer space
  // available)"); a bus that stays full for 300,000 tries must still get every frame.
  StallingBus bus(17, 300'000, sv[0]);
  g_pauses = 0;
  ReplayStats st;
  {
    CandumpReader r(path);
    CHECK(replay_candump(r, bus, 0.0, &st, count_pause) == entries.size());
  }
  CHECK(bus.refused == 300'000);
  CHECK(st.waits == 300'000);
  CHECK(g_pauses == 300'000);
  REQUIRE(bus.sent.size() == entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) CHECK(bus.sent[i] == entries[i].frame);

  // The bus's other end hangs up while its queue is full: the replay names the frame and stops.
  ::close(sv[1]);
  StallingBus gone(5, ~std::uint64_t{0}, sv[0]);
  CandumpReader r(path);
  CHECK_THROWS_WITH_AS(replay_candump(r, gone, 0.0, &st, count_pause), doctest::Contains("frame 5 (the bus is gone"),
                       std::runtime_error);
  CHECK(gone.sent.size() == 5);
  ::close(sv[0]);
  std::remove(path.c_str());
}
