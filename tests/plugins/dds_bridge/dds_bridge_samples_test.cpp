// dds_bridge against a peer that sends bad samples (a raw Cyclone writer in this process):
// a non-finite or out-of-range sample is dropped by the bridge's checks, a sample Cyclone cannot
// decode (more key-points than the IDL's bound) is dropped by Cyclone; each is counted and none
// is written into the port. And the bridge's endpoints as discovery sees them: each with the QoS
// its entry configures.
#include <dds/dds.h>
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "HandState.h"
#include "bridge_fixture.h"
#include "core/port_types/hand.h"
#include "core/port_types/keypoints.h"
#include "raw_writer.h"
#include "rogue_keypoints.h"

using namespace crease;
using crease::test::BridgeHost;
using crease::test::eventually;
using crease::test::raw_writer;
using crease::test::test_domain;
using crease::test::test_topic;

namespace {

struct RoguePoints {
  std::vector<rogue_msgs_msg_dds__Keypoint_> points;
  rogue_msgs_msg_dds__Keypoints_ sample{};
  explicit RoguePoints(std::uint32_t n, std::uint8_t corner = 1) : points(n) {
    for (auto& p : points) p = rogue_msgs_msg_dds__Keypoint_{{1, 2, 3}, {4, 5}, 0.5f, 7, corner, 0, 1};
    sample.frame = n;
    sample.points._length = sample.points._maximum = n;
    sample.points._buffer = points.data();
  }
};
}  // namespace

TEST_CASE("malformed and oversized samples are dropped and counted, never written into the port") {
  BridgeHost b;
  b.add("bridge", "dds_bridge", 0,
        "{domain: " + std::to_string(test_domain()) + ", subscribe: [{topic: " + test_topic("bad/hand_state") +
            ", port: hand_state, type: hand_state}, {topic: " + test_topic("bad/keypoints") +
            ", port: keypoints, type: keypoints}]}");
  b.host.start();
  const dds_entity_t pp = dds_create_participant(static_cast<dds_domainid_t>(test_domain()), nullptr, nullptr);
  REQUIRE(pp > 0);

  // hand_state: one good sample, then a NaN and an unknown health: the port keeps the good one.
  const dds_entity_t hw = raw_writer(pp, &crease_msgs_msg_dds__HandState__desc, test_topic("bad/hand_state"));
  crease_msgs_msg_dds__HandState_ hs{};
  hs.commands_sent = 1;
  REQUIRE(dds_write(hw, &hs) == 0);
  HandState s;
  REQUIRE(eventually([&] { return b.read("hand_state", s).has_data(); }));
  CHECK(s.commands_sent == 1);
  hs.commands_sent = 2;
  hs.position_rad[3] = std::nanf("");
  REQUIRE(dds_write(hw, &hs) == 0);
  hs.position_rad[3] = 0;
  hs.health = 9;
  REQUIRE(dds_write(hw, &hs) == 0);
  REQUIRE(eventually([&] { return b.stats("bridge").topics[0].malformed == 2; }));
  CHECK(b.read("hand_state", s).seq == 1);
  CHECK(s.commands_sent == 1);
  CHECK(b.stats("bridge").topics[0].samples == 1);

  // keypoints: 512 points pass, 513 are more than the IDL's bound (Cyclone refuses to decode
  // them), a corner 7 is out of range.
  const dds_topic_descriptor_t& r = rogue_msgs_msg_dds__Keypoints__desc;
  const dds_topic_descriptor_t look_alike{r.m_size,  r.m_align, r.m_flagset, r.m_nkeys,
                                          "crease_msgs::msg::dds_::Keypoints_", r.m_keys, r.m_nops, r.m_ops,
                                          r.m_meta,  r.type_information, r.type_mapping,
                                          r.restrict_data_representation};
  const dds_entity_t kw = raw_writer(pp, &look_alike, test_topic("bad/keypoints"));
  RoguePoints full(512), over(513), corner(3, 7);
  REQUIRE(dds_write(kw, &full.sample) == 0);
  auto kp = std::make_unique<Keypoints>();
  REQUIRE(eventually([&] { return b.read("keypoints", *kp).has_data(); }));
  CHECK(kp->count == 512);
  REQUIRE(dds_write(kw, &over.sample) == 0);
  REQUIRE(dds_write(kw, &corner.sample) == 0);
  REQUIRE(eventually([&] {
    const BridgeTopicStats t = b.stats("bridge").topics[1];
    return t.undecodable == 1 && t.malformed == 1;
  }));
  CHECK(b.read("keypoints", *kp).seq == 1);
  CHECK(kp->count == 512);
  dds_delete(pp);
  b.host.stop();
}

TEST_CASE("each entry's QoS is its endpoint's: history depth, reliability, deadline and liveliness as configured") {
  BridgeHost h;
  h.add("source", "crease_test_payload_source", 0, "{}");
  h.add("bridge", "dds_bridge", 10,
        "{domain: " + std::to_string(test_domain()) + ", publish: [{port: hand_state, topic: " +
            test_topic("qos_seen/state") + ", reliability: best_effort, depth: 7, deadline_ms: 25, liveliness_ms: 400}]"
            ", subscribe: [{topic: " + test_topic("qos_seen/command") + ", port: hand_command, type: hand_command, "
            "depth: 3}]}");
  const dds_entity_t pp = dds_create_participant(static_cast<dds_domainid_t>(test_domain()), nullptr, nullptr);
  REQUIRE(pp > 0);
  // Discovery's own record of every endpoint in the domain, with its QoS.
  const auto qos_of = [&](dds_entity_t builtin, const std::string& topic) -> dds_qos_t* {
    const dds_entity_t r = dds_create_reader(pp, builtin, nullptr, nullptr);
    REQUIRE(r > 0);
    dds_qos_t* found = nullptr;
    REQUIRE(eventually([&] {
      void* samples[16] = {};
      dds_sample_info_t infos[16];
      const dds_return_t n = dds_read(r, samples, infos, 16, 16);
      for (dds_return_t i = 0; i < n && found == nullptr; ++i) {
        const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
        if (infos[i].valid_data && e->topic_name == "rt/" + topic) {
          found = dds_create_qos();
          dds_copy_qos(found, e->qos);
        }
      }
      if (n > 0) dds_return_loan(r, samples, n);
      return found != nullptr;
    }));
    return found;
  };
  dds_qos_t* w = qos_of(DDS_BUILTIN_TOPIC_DCPSPUBLICATION, test_topic("qos_seen/state"));
  dds_history_kind_t hk;
  std::int32_t depth = 0;
  REQUIRE(dds_qget_history(w, &hk, &depth));
  CHECK(hk == DDS_HISTORY_KEEP_LAST);
  CHECK(depth == 7);
  dds_reliability_kind_t rk;
  dds_duration_t blocking = 0;
  REQUIRE(dds_qget_reliability(w, &rk, &blocking));
  CHECK(rk == DDS_RELIABILITY_BEST_EFFORT);
  dds_duration_t deadline = 0;
  REQUIRE(dds_qget_deadline(w, &deadline));
  CHECK(deadline == DDS_MSECS(25));
  dds_liveliness_kind_t lk;
  dds_duration_t lease = 0;
  REQUIRE(dds_qget_liveliness(w, &lk, &lease));
  CHECK(lk == DDS_LIVELINESS_AUTOMATIC);
  CHECK(lease == DDS_MSECS(400));
  dds_qos_t* r = qos_of(DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, test_topic("qos_seen/command"));
  REQUIRE(dds_qget_history(r, &hk, &depth));
  CHECK(depth == 3);
  REQUIRE(dds_qget_reliability(r, &rk, &blocking));
  CHECK(rk == DDS_RELIABILITY_RELIABLE);  // the default
  REQUIRE(dds_qget_deadline(r, &deadline));
  CHECK(deadline == DDS_INFINITY);
  REQUIRE(dds_qget_liveliness(r, &lk, &lease));
  CHECK(lease == DDS_MSECS(1000));  // the default
  dds_delete_qos(w);
  dds_delete_qos(r);
  dds_delete(pp);
}
