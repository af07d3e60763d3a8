// dds_bridge: carries local latest and queue ports to other daemons and back over Eclipse Cyclone DDS.
//
// Parameters (README.md beside this file has the whole story):
//   dds_config: FILE   CycloneDDS XML: domain, interfaces, peers (relative to the configuration
//                      file; default dds/loopback.xml beside it: loopback only, no multicast)
//   domain: N          domain id (default: the XML's <Domain Id>, 0 when it says "any")
//   thread_priority: N SCHED_FIFO priority of the bridge's publisher thread, below the loops'
//                      (default 0: SCHED_OTHER; Cyclone's own threads take theirs from the XML)
//   publish:   [{port: P, topic: T, type: K, <QoS>}]   each new value of port P -> DDS topic rt/T
//   subscribe: [{topic: T, port: P, type: K, <QoS>}]   samples of rt/T -> port P (this bridge writes it)
//   type: keypoints | hand_state | hand_command | arm_state | arm_command | sheet_state (latest
//                      ports) | sheet_crease | sheet_memorize (queue ports: every event once, in
//                      order; queue_links.h) (optional when port P is already bound: its type)
//   view: joint_state  publish entries of hand_state and arm_state ports: as sensor_msgs/msg/JointState,
//   joint_prefix: r_   its joints named prefix + the URDF's names (joint_state_view.h)
//   QoS keys: reliability, depth, deadline_ms, liveliness_ms (topic_qos.h)
// Ports: the configured ones, and `<instance>_stats` (crease::BridgeStats), its counters.
// Status: degraded while a subscribed topic is stale (never heard, its publisher lost or late; a
// queue topic: while no publisher of it is alive).
// RT: update copies subscribed samples from the links' channels into their ports; the write
// phase copies new values (a queue port: every event) of published ports into the links'
// channels and wakes the publisher thread. Every DDS call runs on the bridge's thread or Cyclone's (bridge_threads.h), never a loop's.
#include <algorithm>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "bridge_threads.h"
#include "core/plugin.h"
#include "core/port_types/bridge_stats.h"
#include "participant.h"
#include "payload_kinds.h"

namespace {

using namespace crease::dds_bridge;

// The payload kind of an entry: its `type:`, or the type of the port as already bound.
const PayloadKind& kind_of(const crease::Params& entry, const crease::PortBinder& ports, const std::string& port) {
  const std::optional<crease::PortInfo> bound = ports.find(port);
  if (entry.has("type")) {
    const std::string key = entry.get<std::string>("type");
    const PayloadKind* k = find_payload_kind(key);
    if (k == nullptr) entry.fail("type", "unknown type '" + key + "' (the bridge carries " + payload_kind_keys() + ")");
    if (bound && (bound->type_name != k->port_type.name || bound->type_version != k->port_type.version))
      entry.fail("type", "type mismatch: port '" + port + "' carries " + bound->type_name + " v" +
                             std::to_string(bound->type_version) + ", not " + key + " (" + k->port_type.name + " v" +
                             std::to_string(k->port_type.version) + ")");
    return *k;
  }
  if (!bound)
    entry.fail("port", "unknown port '" + port + "': no plugin configured before this bridge binds it; name its " +
                           "payload with type: (" + payload_kind_keys() + ")");
  const PayloadKind* k = find_payload_kind(bound->type_name, bound->type_version);
  if (k == nullptr)
    entry.fail("port", "port '" + port + "' carries " + bound->type_name + " v" + std::to_string(bound->type_version) +
                           ", which the bridge cannot carry (" + payload_kind_keys() + ")");
  return *k;
}

class DdsBridge final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    const std::string xml = p.get_path("dds_config", "dds/loopback.xml");
    const int domain = p.has("domain") ? p.get_in_range<int>("domain", 0, 0, Participant::kMaxDomainId) : -1;
    const int priority = p.get_in_range<int>("thread_priority", 0, 0, 98);
    // The domain: `domain` when given (it must be the one the XML names, if it names one), else
    // the XML's, else 0. The file's errors (crease::Error, naming it) are the parameter's.
    int xml_domain = -1;
    try {
      xml_domain = Participant::configured_domain(xml);
    } catch (const crease::Error& e) {
      p.fail("dds_config", e.what());
    }
    if (p.has("domain") && xml_domain >= 0 && domain != xml_domain)
      p.fail("domain", "is " + std::to_string(domain) + " but " + xml + " configures domain " +
                           std::to_string(xml_domain) + " only");
    try {
      participant_ =
          std::make_unique<Participant>(xml, p.has("domain") ? domain : std::max(xml_domain, 0));
    } catch (const crease::Error& e) {
      p.fail("dds_config", e.what());
    }
    const std::vector<crease::Params> pubs = p.list("publish");
    const std::vector<crease::Params> subs = p.list("subscribe");
    if (pubs.empty() && subs.empty()) p.fail({}, "nothing to bridge: give publish or subscribe entries");
    if (pubs.size() + subs.size() > crease::BridgeStats::kCapacity)
      p.fail(pubs.size() > subs.size() ? "publish" : "subscribe",
             "at most " + std::to_string(crease::BridgeStats::kCapacity) + " topics per bridge");

    std::set<std::string> topics;
    for (const crease::Params& e : pubs) add_link(e, ports, topics, true);
    for (const crease::Params& e : subs) add_link(e, ports, topics, false);

    stats_out_ = ports.latest_output<crease::BridgeStats>(instance_name() + "_stats", crease::BridgeStats{});
    stats_ = std::make_unique<crease::BridgeStats>();
    std::vector<Link*> all;
    for (auto& l : publish_) all.push_back(l.get());
    for (auto& l : subscribe_) all.push_back(l.get());
    stats_->count = static_cast<std::uint32_t>(all.size());
    for (std::size_t i = 0; i < all.size(); ++i)
      std::snprintf(stats_->topics[i].topic, crease::BridgeTopicStats::kTopicCapacity, "%s", all[i]->topic().c_str());

    std::vector<PublishLink*> pl;
    for (auto& l : publish_) pl.push_back(l.get());
    std::vector<SubscribeLink*> sl;
    for (auto& l : subscribe_) sl.push_back(l.get());
    if (!pl.empty()) publisher_ = std::make_unique<PublisherThread>(std::move(pl), priority);
    if (!sl.empty()) {
      try {
        subscriber_ = std::make_unique<SubscriberListeners>(std::move(sl));
      } catch (const crease::Error& e) {
        p.fail("subscribe", e.what());
      }
    }
  }

  crease::Status update(const crease::Cycle& cycle) override {
    std::uint32_t stale = 0;
    for (auto& l : subscribe_)
      if (!l->give_rt()) ++stale;
    if (cycle.time_ns - stats_ns_ >= kStatsPeriodNs) {
      stats_ns_ = cycle.time_ns;
      std::size_t i = 0;
      for (auto& l : publish_) l->stats_rt(stats_->topics[i++]);
      for (auto& l : subscribe_) l->stats_rt(stats_->topics[i++]);
      stats_->stale = stale;
      stats_out_.write(*stats_, cycle.time_ns);
    }
    if (stale != stale_) {
      stale_ = stale;
      log_rt(stale != 0 ? crease::rt::LogLevel::warn : crease::rt::LogLevel::info,
             "subscribed topics without fresh data", static_cast<std::int64_t>(stale));
    }
    return stale == 0 ? crease::Status::ok : crease::Status::degraded;
  }

  crease::Status write(const crease::Cycle&) {
    bool any = false;
    for (auto& l : publish_) any = l->take_rt() || any;
    if (any) publisher_->wake_rt();
    return crease::Status::ok;
  }

  void cleanup() override {
    // Listeners and thread first (they use the links), then the links' endpoints, then the participant.
    subscriber_.reset();
    publisher_.reset();
    subscribe_.clear();
    publish_.clear();
    participant_.reset();
  }
  ~DdsBridge() override { cleanup(); }

 private:
  static constexpr std::int64_t kStatsPeriodNs = 10'000'000;  // the stats port at most at 100 Hz

  void add_link(const crease::Params& e, crease::PortBinder& ports, std::set<std::string>& topics, bool publish) {
    const std::string port = e.get<std::string>("port");
    const std::string topic = dds_topic_name(e, crease::BridgeTopicStats::kTopicCapacity - 1);
    if (!topics.insert(topic).second) e.fail("topic", "bridged twice by this instance: " + topic);
    const PayloadKind& kind = kind_of(e, ports, port);
    const TopicQos qos = parse_qos(e, kind.queue);
    // `view: joint_state` (publish only): the port as sensor_msgs/msg/JointState.
    const std::string view = e.get<std::string>("view", "");
    if (e.has("view")) {
      if (!publish) e.fail("view", "a view is published only (a JointState lacks what a hand_state or arm_state port holds)");
      if (view != "joint_state") e.fail("view", "unknown view '" + view + "' (the bridge has joint_state)");
      if (kind.make_joint_state == nullptr)
        e.fail("view", std::string("a ") + kind.key + " port has no joints (joint_state views: " + joint_state_kind_keys() + ")");
    } else if (e.has("joint_prefix")) {
      e.fail("joint_prefix", "only with view: joint_state");
    }
    const std::string prefix = e.get<std::string>("joint_prefix", "");
    try {
      if (publish && !view.empty()) {
        publish_.push_back(kind.make_joint_state(ports, port, participant_->handle(), topic, qos, prefix));
      } else if (publish) {
        publish_.push_back(kind.make_publish(ports, port, participant_->handle(), topic, qos));
      } else {
        subscribe_.push_back(kind.make_subscribe(ports, port, participant_->handle(), topic, qos));
      }
    } catch (const crease::PortError& err) {
      e.fail("port", err.what());
    } catch (const crease::ConfigError&) {
      throw;  // already names its file, line and key
    } catch (const crease::Error& err) {
      e.fail("topic", err.what());  // DDS refused the topic or its endpoint
    }
  }

  std::unique_ptr<Participant> participant_;
  std::vector<std::unique_ptr<PublishLink>> publish_;
  std::vector<std::unique_ptr<SubscribeLink>> subscribe_;
  std::unique_ptr<PublisherThread> publisher_;
  std::unique_ptr<SubscriberListeners> subscriber_;
  crease::LatestOutput<crease::BridgeStats> stats_out_;
  std::unique_ptr<crease::BridgeStats> stats_;
  std::int64_t stats_ns_ = INT64_MIN / 2;
  std::uint32_t stale_ = 0;
};

}  // namespace

CREASE_PLUGIN(DdsBridge, "dds_bridge", "1.0.0")
