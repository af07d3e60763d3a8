// dds_bridge between two processes over loopback: a creased child publishes hand_state and
// keypoints and subscribes hand_command; this process subscribes the first two and answers with
// hand_command (crease_test_hand_echo). Killing the child makes this side's ports stale (its
// writers' liveliness lapses); a new child brings them back.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "bridge_fixture.h"
#include "core/control/control_client.h"
#include "core/port_types/hand.h"
#include "core/port_types/keypoints.h"

using namespace crease;
using crease::test::BridgeHost;
using crease::test::eventually;
using crease::test::test_domain;
using crease::test::test_topic;
namespace fs = std::filesystem;

namespace {
const std::string kQos = ", liveliness_ms: 300";

std::string peer_config() {
  return std::string("plugin_dirs: [") + CREASE_PLUGIN_DIR + "]\n" +
         "daemon: {lock_memory: false}\n"
         "loops:\n"
         "  - {name: control, rate_hz: 1000, priority: 0}\n"
         "plugins:\n"
         "  - {name: source, library: crease_test_payload_source, loop: control, order: 0,\n"
         "     params: {keypoints_every: 10, keypoints_count: 50}}\n"
         "  - name: bridge\n"
         "    library: dds_bridge\n"
         "    loop: control\n"
         "    order: 10\n"
         "    params:\n"
         "      domain: " + std::to_string(test_domain()) + "\n" +
         "      dds_config: " + CREASE_SOURCE_DIR + "/config/dds/loopback.xml\n" +
         "      publish: [{port: hand_state, topic: " + test_topic("proc/hand_state") + kQos + "},\n" +
         "                {port: keypoints, topic: " + test_topic("proc/keypoints") + kQos + "}]\n" +
         "      subscribe: [{topic: " + test_topic("proc/hand_command") + ", port: hand_command, type: hand_command" +
         kQos + "}]\n";
}

// A creased child on peer_config(); its control socket is `sock`.
struct Peer {
  fs::path dir;
  std::string sock;
  pid_t pid = -1;
  explicit Peer(const std::string& name) {
    dir = fs::temp_directory_path() / ("crease_dds_peer_" + std::to_string(::getpid()) + "_" + name);
    fs::create_directories(dir);
    std::ofstream(dir / "peer.yaml") << peer_config();
    sock = (dir / "creased.sock").string();
    std::fflush(nullptr);  // nothing buffered here is written twice
    pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      const std::string log = (dir / "creased.log").string();
      std::freopen(log.c_str(), "w", stdout);
      std::freopen(log.c_str(), "a", stderr);
      ::execl((std::string(CREASE_BIN_DIR) + "/creased").c_str(), "creased", "--config", (dir / "peer.yaml").c_str(),
              "--socket", sock.c_str(), "--report-dir", (dir / "reports").c_str(), "--duration", "60",
              "--no-progress", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    REQUIRE(eventually([&] { return fs::exists(sock); }));
  }
  // The number of values written into the child's port `port` so far.
  std::uint64_t writes(const std::string& port) const {
    control::ControlClient client(sock);
    const nlohmann::json reply = client.request({{"cmd", "ports"}});
    for (const auto& p : reply["result"])
      if (p["name"] == port) return p["writes"].get<std::uint64_t>();
    return 0;
  }
  void kill() {
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
      pid = -1;
    }
  }
  ~Peer() {
    if (pid > 0) {
      ::kill(pid, SIGTERM);
      ::waitpid(pid, nullptr, 0);
    }
    fs::remove_all(dir);
  }
};
}  // namespace

TEST_CASE("two processes over loopback: values cross both ways; a killed peer is stale until a new one starts") {
  BridgeHost b;
  b.add("bridge", "dds_bridge", 0,
        "{domain: " + std::to_string(test_domain()) + ", subscribe: [{topic: " + test_topic("proc/hand_state") +
            ", port: hand_state, type: hand_state" + kQos + "}, {topic: " + test_topic("proc/keypoints") +
            ", port: keypoints, type: keypoints" + kQos + "}], publish: [{topic: " + test_topic("proc/hand_command") +
            ", port: hand_command, type: hand_command" + kQos + "}]}");
  b.add("echo", "crease_test_hand_echo", 10, "{}");  // hand_state -> hand_command
  b.host.start();
  auto peer = std::make_unique<Peer>("first");

  HandState s;
  REQUIRE(eventually([&] { return b.read("hand_state", s).has_data() && s.commands_sent > 100; }));
  CHECK(s.health == DeviceHealth::ok);
  auto kp = std::make_unique<Keypoints>();
  REQUIRE(eventually([&] { return b.read("keypoints", *kp).has_data(); }));
  CHECK(kp->count == 50);
  CHECK(kp->points[49].world_mm[1] == 98.0f);
  // And back: the child's hand_command port is written by its bridge.
  REQUIRE(eventually([&] { return peer->writes("hand_command") > 100; }));

  // Killed: no goodbye, its writers' leases (300 ms) lapse.
  peer->kill();
  REQUIRE(eventually([&] { return b.stats("bridge").stale == 2; }));
  const BridgeStats st = b.stats("bridge");
  CHECK(st.topics[1].direction == BridgeTopicStats::subscribe);  // after the publish entry
  CHECK(st.topics[1].liveliness_lost > 0);
  const std::uint64_t seq = b.read("hand_state", s).seq;
  const std::uint64_t degraded = b.degraded("bridge");
  REQUIRE(eventually([&] { return b.degraded("bridge") > degraded + 100; }));
  CHECK(b.read("hand_state", s).seq == seq);

  // A new peer: fresh again.
  peer = std::make_unique<Peer>("second");
  REQUIRE(eventually([&] { return b.stats("bridge").stale == 0 && b.read("hand_state", s).seq > seq; }));
  CHECK(b.state("bridge") == RunState::active);
  REQUIRE(eventually([&] { return peer->writes("hand_command") > 100; }));
  b.host.stop();
}
