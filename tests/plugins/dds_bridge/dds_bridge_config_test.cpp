// dds_bridge configuration errors: each names the file, line and key, and leaves the host as
// it was (no peer needed).
#include <doctest/doctest.h>

#include <pthread.h>
#include <sched.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "bridge_fixture.h"

using crease::test::BridgeHost;
using crease::test::test_domain;

namespace {
const std::string kFile = std::string(CREASE_SOURCE_DIR) + "/config/test.yaml";

std::string error_of(BridgeHost& h, const std::string& yaml) {
  try {
    h.add("bridge", "dds_bridge", 10, yaml);
  } catch (const std::exception& e) {
    return e.what();
  }
  h.host.unload("bridge");
  return "no error";
}
bool names(const std::string& error, const std::string& key, const std::string& reason) {
  const bool ok = error.find(kFile + ":1:") != std::string::npos && error.find("bridge.params" + (key.empty() ? "" : "." + key) + ": ") != std::string::npos &&
                  error.find(reason) != std::string::npos;
  if (!ok) MESSAGE(error);
  return ok;
}
std::string d() { return "{domain: " + std::to_string(test_domain()) + ", "; }
std::string temp_xml(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("crease_dds_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}
}  // namespace

TEST_CASE("entries: unknown type or port, a type mismatch, a port with another writer, bad QoS, bad topics") {
  BridgeHost h;
  h.add("source", "crease_test_payload_source", 0, "{}");  // writes hand_state (crease.HandState)
  CHECK(names(error_of(h, d() + "subscribe: [{topic: a, port: p, type: hand_stat}]}"),
              "subscribe[0].type",
              "unknown type 'hand_stat' (the bridge carries keypoints, hand_state, hand_command, "
              "arm_state, "
              "arm_command, sheet_state, sheet_crease, sheet_memorize, world_shapes)"));
  CHECK(names(error_of(h, d() + "publish: [{port: nothing, topic: a}]}"), "publish[0].port",
              "unknown port 'nothing': no plugin configured before this bridge binds it"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a, type: keypoints}]}"), "publish[0].type",
              "type mismatch: port 'hand_state' carries crease.HandState v1, not keypoints (crease.Keypoints v1)"));
  CHECK(names(error_of(h, d() + "subscribe: [{topic: a, port: hand_state}]}"), "subscribe[0].port",
              "instance 'source' already does"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a, reliability: sometimes}]}"),
              "publish[0].reliability", "expected reliable or best_effort, got 'sometimes'"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a, depth: 0}]}"), "publish[0].depth",
              "must be in [1, 1000], got 0"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a, deadline_ms: -5}]}"),
              "publish[0].deadline_ms", "must be in [0, 3600000]"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a, liveliness: 5}]}"), "publish[0].liveliness",
              "unknown parameter"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: 'a//b'}]}"), "publish[0].topic",
              "'a//b' has an empty token"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: 'a/2b'}]}"), "publish[0].topic",
              "has a token starting with a digit"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a}], subscribe: [{topic: a, port: q, type: "
                                "hand_state}]}"),
              "subscribe[0].topic", "bridged twice by this instance: rt/a"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state}]}"), "publish[0].topic", "required parameter is missing"));
  CHECK(names(error_of(h, d() + "publish: {port: hand_state}}"), "publish", "expected a list of maps"));
  CHECK(names(error_of(h, "{domain: 7}"), "", "nothing to bridge"));
  // Views: publish only, of ports with joints, known by name; joint_prefix only with one.
  CHECK(names(error_of(h, d() + "subscribe: [{topic: a, port: q, type: hand_state, view: joint_state}]}"),
              "subscribe[0].view", "a view is published only"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a, view: ros}]}"), "publish[0].view",
              "unknown view 'ros' (the bridge has joint_state)"));
  CHECK(names(error_of(h, d() + "publish: [{port: kp, topic: a, type: keypoints, view: joint_state}]}"),
              "publish[0].view", "a keypoints port has no joints (joint_state views: hand_state, arm_state)"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a, joint_prefix: r_}]}"),
              "publish[0].joint_prefix", "only with view: joint_state"));
  // Queue topics (events): reliable, no deadline; a queue port is not a latest port.
  CHECK(names(error_of(h, d() + "publish: [{port: e, topic: a, type: sheet_crease, reliability: best_effort}]}"),
              "publish[0].reliability", "a queue topic is reliable"));
  CHECK(names(error_of(h, d() + "subscribe: [{topic: a, port: e, type: sheet_memorize, deadline_ms: 50}]}"),
              "subscribe[0].deadline_ms", "a queue topic has no deadline"));
  CHECK(names(error_of(h, d() + "publish: [{port: hand_state, topic: a, type: sheet_crease}]}"), "publish[0].type",
              "type mismatch: port 'hand_state' carries crease.HandState v1, not sheet_crease "
              "(crease.SheetCreaseEvent v1)"));
  CHECK(names(error_of(h, d() + "subscribe: [{topic: a, port: e, type: sheet_crease, view: joint_state}]}"),
              "subscribe[0].view", "a view is published only"));
  // No domain: the XML's (dds/loopback.xml says any: domain 0), as config/split/ runs.
  CHECK(error_of(h, "{publish: [{port: hand_state, topic: " + crease::test::test_topic("no_domain") + "}]}") ==
        "no error");
  // Nothing was left behind by the refusals: a good entry binds the same ports.
  CHECK(error_of(h, d() + "publish: [{port: hand_state, topic: a}], subscribe: [{topic: b, port: hand_state_2, type: "
                          "hand_state}]}") == "no error");
}

TEST_CASE("the CycloneDDS XML: unreadable, refused by Cyclone, another domain, or another file for a domain in use") {
  BridgeHost h;
  h.add("source", "crease_test_payload_source", 0, "{}");
  const std::string link = "publish: [{port: hand_state, topic: a}]}";
  CHECK(names(error_of(h, d() + "dds_config: /nonexistent/cyclone.xml, " + link), "dds_config",
              "cannot read /nonexistent/cyclone.xml: No such file or directory"));
  const std::string bad = temp_xml("bad.xml", "<CycloneDDS><Domain Id=\"any\"><General><Bogus/></General></Domain></CycloneDDS>");
  const std::string refused = error_of(h, d() + "dds_config: " + bad + ", " + link);
  CHECK(names(refused, "dds_config", "CycloneDDS refused " + bad + " for domain"));
  CHECK(refused.find("Bogus") != std::string::npos);  // Cyclone's own reason
  const std::string none = temp_xml("none.xml", "<CycloneDDS></CycloneDDS>");
  CHECK(names(error_of(h, d() + "dds_config: " + none + ", " + link), "dds_config", "has no <Domain> element"));
  const std::string three = temp_xml("three.xml", "<CycloneDDS><Domain Id=\"3\"/></CycloneDDS>");
  CHECK(names(error_of(h, "{domain: 4, dds_config: " + three + ", " + link), "domain",
              "is 4 but " + three + " configures domain 3 only"));

  // A second bridge on the domain in use must bring the same configuration.
  h.add("first", "dds_bridge", 20, d() + "subscribe: [{topic: c, port: c, type: hand_state}]}");
  const std::string other = temp_xml("other.xml", "<CycloneDDS><Domain Id=\"any\"><General><AllowMulticast>false"
                                                  "</AllowMulticast></General></Domain></CycloneDDS>");
  CHECK(names(error_of(h, d() + "dds_config: " + other + ", " + link), "dds_config", "already runs in this process with"));
  for (const auto& f : {bad, none, three, other}) std::filesystem::remove(f);
}

TEST_CASE("thread_priority: the publisher thread runs SCHED_FIFO at it (where permitted); out of range is refused") {
  BridgeHost h;
  h.add("source", "crease_test_payload_source", 0, "{}");
  CHECK(names(error_of(h, d() + "thread_priority: 99, publish: [{port: hand_state, topic: a}]}"), "thread_priority",
              "must be in [0, 98], got 99"));
  sched_param probe{};
  probe.sched_priority = 1;
  pthread_t self = pthread_self();
  int policy = 0;
  sched_param was{};
  pthread_getschedparam(self, &policy, &was);
  if (pthread_setschedparam(self, SCHED_FIFO, &probe) != 0) {
    MESSAGE("SCHED_FIFO not permitted here: the priority itself is not checked");
    return;
  }
  pthread_setschedparam(self, policy, &was);
  h.add("bridge", "dds_bridge", 10, d() + "thread_priority: 7, publish: [{port: hand_state, topic: a}]}");
  bool found = false;
  REQUIRE(crease::test::eventually([&] {
    for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
      std::ifstream comm(task.path() / "comm");
      std::string name;
      std::getline(comm, name);
      if (name != "dds-publish") continue;
      sched_param sp{};
      const pid_t tid = static_cast<pid_t>(std::stol(task.path().filename().string()));
      found = sched_getscheduler(tid) == SCHED_FIFO && sched_getparam(tid, &sp) == 0 && sp.sched_priority == 7;
    }
    return found;
  }));
}
