// dds_bridge between two hosts of one process (Cyclone delivers between them inside the
// process): values cross both ways, a silent or lost publisher makes the port stale and the
// bridge degraded until it returns, QoS mismatches and bad samples are counted, configuration
// errors name the file and key, and the RT part allocates nothing.
#include <doctest/doctest.h>

#include <cmath>

#include "bridge_fixture.h"
#include "core/port_types/hand.h"
#include "core/port_types/keypoints.h"
#include "rt/alloc_guard.h"

using namespace crease;
using crease::test::BridgeHost;
using crease::test::eventually;
using crease::test::test_domain;
using crease::test::test_topic;

namespace {
std::string bridge_params(const std::string& links) {
  return "{domain: " + std::to_string(test_domain()) + ", " + links + "}";
}
// A publishes hand_state (1 kHz) and keypoints (every 10 cycles, 300 points) on topic `tag`.
void add_publisher(BridgeHost& a, const std::string& tag, const std::string& qos = "") {
  a.add("source", "crease_test_payload_source", 0, "{keypoints_every: 10, keypoints_count: 300}");
  a.add("bridge", "dds_bridge", 10,
        bridge_params("publish: [{port: hand_state, topic: " + test_topic(tag + "/hand_state") + qos +
                      "}, {port: keypoints, topic: " + test_topic(tag + "/keypoints") + "}]"));
}
void add_subscriber(BridgeHost& b, const std::string& tag, const std::string& qos = "") {
  b.add("bridge", "dds_bridge", 0,
        bridge_params("subscribe: [{topic: " + test_topic(tag + "/hand_state") +
                      ", port: hand_state, type: hand_state" + qos + "}, {topic: " + test_topic(tag + "/keypoints") +
                      ", port: keypoints, type: keypoints}]"));
}
}  // namespace

TEST_CASE("values published on one host arrive on the other's ports; the RT part allocates nothing") {
  BridgeHost a, b;
  add_publisher(a, "arrive");
  add_subscriber(b, "arrive");
  a.host.start();
  b.host.start();
  HandState s;
  REQUIRE(eventually([&] { return b.read("hand_state", s).has_data() && s.commands_sent > 100; }));
  CHECK(s.device_time_us == static_cast<std::uint32_t>(s.commands_sent));
  CHECK(s.health == DeviceHealth::ok);
  CHECK(s.position_rad[7] == doctest::Approx(0.07 + 1e-6 * double(s.commands_sent % 1000)).epsilon(1e-5));
  auto kp = std::make_unique<Keypoints>();
  REQUIRE(eventually([&] { return b.read("keypoints", *kp).has_data(); }));
  CHECK(kp->count == 300);
  CHECK(kp->frame % 10 == 0);
  CHECK(kp->points[299].world_mm[2] == 897.0f);
  CHECK(kp->points[299].corner == 4);
  CHECK(kp->points[299].marker_id == 59);

  // Steady state: both loop threads (RT-marked) run the bridges; nothing allocates.
  REQUIRE(rt::alloc_hooks_installed());
  const auto allocations = rt::rt_allocation_count();
  const std::uint64_t degraded = b.degraded("bridge");
  const std::uint64_t seen = s.commands_sent;
  REQUIRE(eventually([&] { return b.read("hand_state", s).has_data() && s.commands_sent > seen + 300; }));
  CHECK(rt::rt_allocation_count() == allocations);
  CHECK(b.degraded("bridge") == degraded);  // fresh all along

  const BridgeStats st = b.stats("bridge");
  REQUIRE(st.count == 2);
  CHECK(std::string(st.topics[0].topic) == "rt/" + test_topic("arrive/hand_state"));
  CHECK(st.topics[0].direction == BridgeTopicStats::subscribe);
  CHECK(st.topics[0].stale == 0);
  CHECK(st.topics[0].matched == 1);
  CHECK(st.topics[0].port_writes > 300);
  CHECK(st.topics[0].malformed + st.topics[0].oversized + st.topics[0].undecodable == 0);
  const BridgeStats sa = a.stats("bridge");
  CHECK(sa.topics[0].direction == BridgeTopicStats::publish);
  CHECK(sa.topics[0].samples > 300);
  CHECK(sa.topics[1].samples > 30);
  CHECK(sa.topics[0].lost == 0);
  b.host.stop();
  a.host.stop();
}
