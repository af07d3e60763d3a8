#include "drivers/can/socketcand_bridge.h"

#include <doctest/doctest.h>
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"

extern char** environ;
using namespace crease::drivers;

namespace {
// python-can 4.1 peer: announces itself with frame 0x7FF, then echoes every frame with id + 1
// after checking its 4-byte little-endian counter.
constexpr const char* kPeer = R"PY(
import can, sys, time
port, n = int(sys.argv[1]), int(sys.argv[2])
bus = can.Bus(interface='socketcand', channel='can0', host='127.0.0.1', port=port)
time.sleep(0.1)
bus.send(can.Message(arbitration_id=0x7FF, data=b'hello', is_extended_id=False))
bad = 0
for i in range(n):
    m = bus.recv(10)
    if m is None:
        print('timeout at', i); sys.exit(3)
    if int.from_bytes(bytes(m.data[:4]), 'little') != i:
        bad += 1
    ext = m.arbitration_id > 0x7FF
    bus.send(can.Message(arbitration_id=m.arbitration_id + 1, data=m.data, is_extended_id=ext))
print('peer ok', n, 'bad', bad)
bus.shutdown()
sys.exit(0 if bad == 0 else 4)
)PY";
}  // namespace

TEST_CASE("python-can exchanges 2 x 10,000 frames with a mock bus through the bridge") {
  const std::string bus_name = "scd-" + std::to_string(::getpid());
  MockCanBroker broker({bus_name, 0, 0, false});
  MockCanBus bridge_node({bus_name, 50, 0, 0});
  MockCanBus test_node({bus_name, 51, 0, 0});
  SocketcandBridge bridge(bridge_node, 0);
  const std::string script = "/tmp/crease_scd_peer_" + std::to_string(::getpid()) + ".py";
  std::ofstream(script) << kPeer;
  constexpr int kFrames = 10'000;
  const std::string port = std::to_string(bridge.port()), n = std::to_string(kFrames);
  const std::string out = script + ".out";
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  const char* argv[] = {"/usr/bin/python3", script.c_str(), port.c_str(), n.c_str(), nullptr};
  pid_t pid = -1;
  REQUIRE(posix_spawn(&pid, argv[0], &fa, nullptr, const_cast<char**>(argv), environ) == 0);
  posix_spawn_file_actions_destroy(&fa);

  auto recv_wait = [&](RxFrame& rx, int ms) {
    for (;;) {
      const RecvResult r = test_node.try_receive(rx);
      if (r == RecvResult::frame) return true;
      if (r == RecvResult::error) return false;
      pollfd p{test_node.fd(), POLLIN, 0};
      if (::poll(&p, 1, ms) <= 0) return false;
    }
  };
  RxFrame rx;
  REQUIRE(recv_wait(rx, 15'000));  // python-can connected and in rawmode
  CHECK(rx.frame.id() == 0x7FF);
  CHECK(rx.frame.len == 5);

  std::mt19937 rng(5);
  std::vector<CanFrame> sent;
  sent.reserve(kFrames);
  int echoed = 0, mismatches = 0;
  while (echoed < kFrames) {
    while (static_cast<int>(sent.size()) < kFrames && static_cast<int>(sent.size()) - echoed < 64) {
      const int i = static_cast<int>(sent.size());
      std::uint8_t b[8];
      for (int k = 0; k < 4; ++k) b[k] = static_cast<std::uint8_t>(i >> (8 * k));
      for (int k = 4; k < 8; ++k) b[k] = static_cast<std::uint8_t>(rng());
      const std::uint32_t id = (i % 5 == 0) ? ((0x100000u + static_cast<std::uint32_t>(i) * 2) | CAN_EFF_FLAG)
                                            : 0x100u + static_cast<std::uint32_t>(i % 0x300) * 2;
      const CanFrame f = CanFrame::classic(id, std::span<const std::uint8_t>(b, 4 + static_cast<std::size_t>(i % 5)));
      if (test_node.send(f) != SendResult::ok) break;
      sent.push_back(f);
    }
    if (!recv_wait(rx, 10'000)) break;
    const CanFrame& want = sent[static_cast<std::size_t>(echoed)];
    CanFrame expect = want;
    expect.can_id = (want.id() + 1) | (want.is_extended() ? CAN_EFF_FLAG : 0);
    if (!(rx.frame == expect)) ++mismatches;
    ++echoed;
  }
  int status = -1;
  ::waitpid(pid, &status, 0);
  std::ifstream in(out);
  std::stringstream peer;
  peer << in.rdbuf();
  MESSAGE("python-can peer: " << peer.str());
  CHECK(echoed == kFrames);
  CHECK(mismatches == 0);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(bridge.stats().to_clients == kFrames);
  CHECK(bridge.stats().from_clients == kFrames + 1);
  std::remove(script.c_str());
  std::remove(out.c_str());
}
