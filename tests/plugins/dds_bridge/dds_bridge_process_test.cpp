// dds_bridge between two processes over loopback: a creased child publishes hand_state and
// keypoints and subscribes hand_command; this process subscribes the first two and answers with
// hand_command (crease_test_hand_echo). Killing the child makes this side's ports stale (its
// writers' liveliness lapses); a new child brings them back. And the sheet model's edits as
// config/split/ carries them: this process publishes sheet_crease and sheet_memorize (queue
// ports), a creased child's bridge feeds them to its sheet_model, whose sheet_state comes back:
// the model holds exactly the creases of the edits applied once each, in order; unbridged, none.
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
#include "core/port_types/sheet_state.h"

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

// A sheet model at 60 Hz fed by its bridge (before it, order 5 < 10, as config/split/vision.yaml
// runs them) with the edits of `crease` (unless empty) and `memorize`, its sheet_state published.
std::string model_config(const std::string& crease, const std::string& memorize) {
  const std::string edit = ", liveliness_ms: 300}";
  return std::string("plugin_dirs: [") + CREASE_PLUGIN_DIR + "]\n" +
         "daemon: {lock_memory: false}\n"
         "loops:\n"
         "  - {name: model, rate_hz: 60, priority: 0}\n"
         "plugins:\n"
         "  - {name: sheet, library: sheet_model, loop: model, order: 10,\n"
         "     params: {substeps: 2, self_collision: 0}, ports: {crease: sheet_crease, memorize: sheet_memorize}}\n"
         "  - name: bridge\n"
         "    library: dds_bridge\n"
         "    loop: model\n"
         "    order: 5\n"
         "    params:\n"
         "      domain: " + std::to_string(test_domain()) + "\n" +
         "      dds_config: " + CREASE_SOURCE_DIR + "/config/dds/loopback.xml\n" +
         "      publish: [{port: sheet_state, topic: " + test_topic("proc/sheet_state") + kQos + "}]\n" +
         "      subscribe: [" +
         (crease.empty() ? "" : "{topic: " + test_topic(crease) + ", port: sheet_crease, type: sheet_crease" + edit + ", ") +
         "{topic: " + test_topic(memorize) + ", port: sheet_memorize, type: sheet_memorize" + edit + "]\n";
}

// A creased child on `config` (default peer_config()); its control socket is `sock`.
struct Peer {
  fs::path dir;
  std::string sock;
  pid_t pid = -1;
  explicit Peer(const std::string& name, const std::string& config = peer_config()) {
    dir = fs::temp_directory_path() / ("crease_dds_peer_" + std::to_string(::getpid()) + "_" + name);
    fs::create_directories(dir);
    std::ofstream(dir / "peer.yaml") << config;
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
  // The number of values written into the child's port `port` so far (`key` "pushed": events
  // pushed into a queue port).
  std::uint64_t writes(const std::string& port, const char* key = "writes") const {
    control::ControlClient client(sock);
    const nlohmann::json reply = client.request({{"cmd", "ports"}});
    for (const auto& p : reply["result"])
      if (p["name"] == port) return p[key].get<std::uint64_t>();
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

namespace {
// This process: publishes the edits on `crease` and `memorize`, reads the child's sheet_state.
void add_editor(BridgeHost& b, const std::string& crease, const std::string& memorize) {
  b.add("bridge", "dds_bridge", 0,
        "{domain: " + std::to_string(test_domain()) + ", publish: [{port: sheet_crease, topic: " + test_topic(crease) +
            ", type: sheet_crease" + kQos + "}, {port: sheet_memorize, topic: " + test_topic(memorize) +
            ", type: sheet_memorize" + kQos + "}], subscribe: [{topic: " + test_topic("proc/sheet_state") +
            ", port: sheet_state, type: sheet_state" + kQos + "}]}");
}
SheetCreaseEvent add(float v) {
  SheetCreaseEvent e;
  e.op = SheetCreaseEvent::Op::add;
  e.a_mm[0] = 0;
  e.a_mm[1] = v;
  e.b_mm[0] = 210;
  e.b_mm[1] = v;
  return e;
}
// The creases of the child's model as (id, v of its first end) pairs, once its state is at
// least `step`.
std::vector<std::pair<int, float>> creases(const SheetState& s) {
  std::vector<std::pair<int, float>> out;
  for (std::uint32_t k = 0; k < s.crease_count; ++k) out.emplace_back(s.crease_id[k], s.crease_mm[k][1]);
  return out;
}
}  // namespace

TEST_CASE("two processes: the sheet model's edits cross once each, in order; unbridged, the model hears none") {
  for (const bool bridged : {true, false}) {
    CAPTURE(bridged);
    const std::string tag = bridged ? "proc/edits" : "proc/unbridged";
    BridgeHost b(250.0);
    add_editor(b, tag + "/crease", tag + "/memorize");
    b.host.start();
    // The failing variant: the child's bridge does not subscribe the creases.
    Peer peer(bridged ? "model" : "model_unbridged",
              model_config(bridged ? tag + "/crease" : "", tag + "/memorize"));
    auto sheet = std::make_unique<SheetState>();
    REQUIRE(eventually([&] { return b.read("sheet_state", *sheet).has_data() && sheet->step > 0; }));
    CHECK(sheet->crease_count == 0);
    // Both edit topics matched (a volatile topic keeps nothing for a subscriber that comes later).
    REQUIRE(eventually([&] {
      const BridgeStats st = b.stats("bridge");
      return st.topics[0].matched == (bridged ? 1 : 0) && st.topics[1].matched == 1;
    }));

    // Add at v = 100 (id 0) and 150 (id 1), remove id 0, add at 200 (id 0 again), memorize.
    // Applied once each and in this order the model holds {0: 200, 1: 150}; out of order or
    // repeated it would hold others (a remove before its add removes nothing).
    rt::QueueChannel* crease_q = b.host.ports().find_queue("sheet_crease");
    rt::QueueChannel* memorize_q = b.host.ports().find_queue("sheet_memorize");
    REQUIRE(crease_q != nullptr);
    REQUIRE(memorize_q != nullptr);
    SheetCreaseEvent remove;
    remove.op = SheetCreaseEvent::Op::remove;
    remove.id = 0;
    for (const SheetCreaseEvent& e : {add(100), add(150), remove, add(200)}) REQUIRE(crease_q->try_push(&e));
    SheetMemorizeEvent m;
    m.whole_sheet = true;
    REQUIRE(memorize_q->try_push(&m));
    REQUIRE(eventually([&] { return peer.writes("sheet_memorize", "pushed") == 1; }));
    if (bridged) {
      REQUIRE(eventually([&] { return peer.writes("sheet_crease", "pushed") == 4; }));
      REQUIRE(eventually([&] { return b.read("sheet_state", *sheet).has_data() && sheet->crease_count == 2; }));
    }
    // Later model cycles: nothing more arrives, the model's creases stay.
    const std::uint64_t step = sheet->step;
    REQUIRE(eventually([&] { return b.read("sheet_state", *sheet).has_data() && sheet->step > step + 60; }));
    CHECK(peer.writes("sheet_memorize", "pushed") == 1);
    if (bridged) {
      CHECK(peer.writes("sheet_crease", "pushed") == 4);
      const std::vector<std::pair<int, float>> want = {{0, 200.0f}, {1, 150.0f}};
      CHECK(creases(*sheet) == want);
      CHECK(b.stats("bridge").topics[0].samples == 4);
      CHECK(b.stats("bridge").topics[0].lost == 0);
    } else {
      CHECK(sheet->crease_count == 0);
      CHECK(b.stats("bridge").topics[0].lost == 4);  // written with no subscriber: counted, not heard
    }
    b.host.stop();
  }
}
