// dds_bridge's JointState view, as a ROS 2 node would see it: a plain Cyclone reader of
// sensor_msgs::msg::dds_::JointState_ (the type rmw_cyclonedds puts on the wire for
// sensor_msgs/msg/JointState) on the topics of `view: joint_state` entries. An arm's state comes
// in from a raw writer of crease_msgs ArmState_ (the arm_state type over the wire), a hand's from
// the test source plugin; each goes out with the URDF's joint names behind its prefix, in the
// payload's joint order, NaN for a joint not measured.
#include <dds/dds.h>
#include <doctest/doctest.h>
#include <time.h>

#include <cmath>
#include <string>

#include "ArmState.h"
#include "JointState.h"
#include "bridge_fixture.h"
#include "core/port_types/arm.h"
#include "core/port_types/hand.h"

using namespace crease;
using crease::test::BridgeHost;
using crease::test::eventually;
using crease::test::test_domain;
using crease::test::test_topic;

namespace {

dds_qos_t* peer_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_MSECS(1000));  // the bridge's default lease: matches either way
  return q;
}

dds_entity_t endpoint(dds_entity_t pp, const dds_topic_descriptor_t* type, const std::string& topic, bool writer) {
  dds_qos_t* q = peer_qos();
  const dds_entity_t t = dds_create_topic(pp, type, ("rt/" + topic).c_str(), q, nullptr);
  REQUIRE(t > 0);
  const dds_entity_t e = writer ? dds_create_writer(pp, t, q, nullptr) : dds_create_reader(pp, t, q, nullptr);
  dds_delete_qos(q);
  REQUIRE(e > 0);
  return e;
}

// The newest JointState on `reader`, taken into `out` by FN (while the loan is held).
template <class Fn>
bool take_joint_state(dds_entity_t reader, Fn&& fn) {
  void* samples[1] = {nullptr};
  dds_sample_info_t info[1];
  const dds_return_t n = dds_take(reader, samples, info, 1, 1);
  if (n <= 0) return false;
  const bool valid = info[0].valid_data;
  if (valid) fn(*static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[0]));
  dds_return_loan(reader, samples, n);
  return valid;
}

double realtime_s() {
  timespec t{};
  clock_gettime(CLOCK_REALTIME, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

TEST_CASE("view: joint_state: arm and hand states as sensor_msgs/msg/JointState, read by a plain Cyclone reader") {
  BridgeHost b;
  const std::string dom = "{domain: " + std::to_string(test_domain()) + ", ";
  b.add("source", "crease_test_payload_source", 0, "{}");  // hand_state, every cycle
  b.add("arm_in", "dds_bridge", 5,
        dom + "subscribe: [{topic: " + test_topic("js/arm_state") + ", port: arm_state, type: arm_state}]}");
  b.add("views", "dds_bridge", 10,
        dom + "publish: [{port: arm_state, topic: " + test_topic("js/arm_joints") + ", view: joint_state, "
              "joint_prefix: l_}, {port: hand_state, topic: " + test_topic("js/hand_joints") +
              ", view: joint_state, joint_prefix: r_}]}");
  b.host.start();
  const dds_entity_t pp = dds_create_participant(static_cast<dds_domainid_t>(test_domain()), nullptr, nullptr);
  REQUIRE(pp > 0);
  const dds_entity_t arm_writer = endpoint(pp, &crease_msgs_msg_dds__ArmState__desc, test_topic("js/arm_state"), true);
  const dds_entity_t arm_joints = endpoint(pp, &sensor_msgs_msg_dds__JointState__desc, test_topic("js/arm_joints"), false);
  const dds_entity_t hand_joints =
      endpoint(pp, &sensor_msgs_msg_dds__JointState__desc, test_topic("js/hand_joints"), false);

  // An arm state over the wire (crease_msgs ArmState_), joint 3 not measured.
  crease_msgs_msg_dds__ArmState_ arm{};
  timespec mono{};
  clock_gettime(CLOCK_MONOTONIC, &mono);
  arm.timestamp_ns = static_cast<std::int64_t>(mono.tv_sec) * 1'000'000'000 + mono.tv_nsec;
  arm.valid = 0x77;
  arm.drive_state = 4;
  for (int j = 0; j < 7; ++j) {
    arm.position_rad[j] = 0.1f * static_cast<float>(j + 1);
    arm.velocity_rad_s[j] = -0.01f * static_cast<float>(j + 1);
  }
  ArmState port;
  REQUIRE(eventually([&] {  // written until the bridge's reader has matched and taken one
    REQUIRE(dds_write(arm_writer, &arm) == 0);
    return b.read("arm_state", port).has_data();
  }));
  CHECK(port.valid == 0x77);
  CHECK(port.velocity_rad_s[6] == -0.07f);

  bool seen = false;
  REQUIRE(eventually([&] {
    REQUIRE(dds_write(arm_writer, &arm) == 0);  // a new value each time (the reader matches late)
    return take_joint_state(arm_joints, [&](const sensor_msgs_msg_dds__JointState_& js) {
      REQUIRE(js.name._length == 7);
      REQUIRE(js.position._length == 7);
      REQUIRE(js.velocity._length == 7);
      CHECK(js.effort._length == 0);
      const char* names[] = {"l_S1", "l_S2", "l_S3", "l_E1", "l_E2", "l_W1", "l_W2"};
      for (int j = 0; j < 7; ++j) {
        CAPTURE(j);
        CHECK(std::string(js.name._buffer[j]) == names[j]);
        if (j == 3) {
          CHECK(std::isnan(js.position._buffer[j]));
          CHECK(std::isnan(js.velocity._buffer[j]));
        } else {
          CHECK(js.position._buffer[j] == static_cast<double>(0.1f * static_cast<float>(j + 1)));
          CHECK(js.velocity._buffer[j] == static_cast<double>(-0.01f * static_cast<float>(j + 1)));
        }
      }
      CHECK(std::string(js.header.frame_id).empty());
      // ROS time: the monotonic stamp on the realtime clock (a monotonic stamp read as ROS
      // time would be decades off).
      const double stamp = js.header.stamp.sec + 1e-9 * js.header.stamp.nanosec;
      CHECK(std::abs(stamp - realtime_s()) < 60.0);
      seen = true;
    });
  }));
  CHECK(seen);

  // The hand: its 20 joints, the wrist first, the thumb last; a hand reports no velocities.
  REQUIRE(eventually([&] {
    return take_joint_state(hand_joints, [&](const sensor_msgs_msg_dds__JointState_& js) {
      REQUIRE(js.name._length == 20);
      REQUIRE(js.position._length == 20);
      CHECK(js.velocity._length == 0);
      CHECK(js.effort._length == 0);
      CHECK(std::string(js.name._buffer[0]) == "r_WRJ2");
      CHECK(std::string(js.name._buffer[2]) == "r_FFJ4");
      CHECK(std::string(js.name._buffer[19]) == "r_THJ1");
      for (int j = 0; j < 20; ++j) CHECK(std::abs(js.position._buffer[j] - 0.01 * j) < 2e-3);
    });
  }));
  dds_delete(pp);
  b.host.stop();
}
