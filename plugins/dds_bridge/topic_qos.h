// One bridged topic's name and QoS, from its entry in the bridge's configuration (non-RT).
//
// Entry keys (both directions):
//   topic: crease/left_hand/state   ROS 2 name; the DDS topic is "rt/" + name (ROS 2's convention)
//   reliability: reliable | best_effort      default reliable
//   depth: N                 KEEP_LAST history depth, 1..1000, default 1 (queue topics: default
//                            KEEP_ALL, every event kept until each subscriber acknowledged it)
//   deadline_ms: T           a sample at least every T ms, else the subscribed port goes stale;
//                            0 (default) = no deadline
//   liveliness_ms: T         automatic liveliness lease: a publisher silent for T ms (its process
//                            gone) makes the subscribed port stale; 0 = infinite, default 1000
// Publisher and subscriber must agree as DDS requires (a reliable subscriber does not match a
// best-effort publisher; the publisher's deadline and lease must not exceed the subscriber's):
// a mismatch shows as `incompatible_qos` in the bridge's counters and no data.
// A queue topic (events: sheet_crease, sheet_memorize) is reliable and has no deadline (events
// come when they come): best_effort or deadline_ms on its entry is a configuration error.
#pragma once

#include <dds/dds.h>

#include <cstdint>
#include <memory>
#include <string>

#include "core/params.h"

namespace crease::dds_bridge {

struct TopicQos {
  bool reliable = true;
  int depth = 1;
  bool keep_all = false;           // KEEP_ALL history (depth unused)
  std::int64_t deadline_ns = 0;    // 0: none
  std::int64_t liveliness_ns = 0;  // 0: infinite
};

struct QosDeleter {
  void operator()(dds_qos_t* q) const noexcept { dds_delete_qos(q); }
};
using QosPtr = std::unique_ptr<dds_qos_t, QosDeleter>;

// The DDS topic name for a ROS 2 topic name: "rt/" + name without its leading '/'. Throws
// ConfigError (via entry.fail) unless the name follows ROS 2's rules: tokens of [A-Za-z0-9_]
// not starting with a digit, separated by single '/', at most `max_length` characters in all.
[[nodiscard]] std::string dds_topic_name(const Params& entry, std::size_t max_length);

// The entry's QoS keys (`events`: a queue topic's rules); throws ConfigError naming the key.
[[nodiscard]] TopicQos parse_qos(const Params& entry, bool events = false);

// Reader and writer QoS (history, reliability, deadline, liveliness; durability volatile).
[[nodiscard]] QosPtr make_qos(const TopicQos& q);

}  // namespace crease::dds_bridge
