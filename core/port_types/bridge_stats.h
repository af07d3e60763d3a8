// Port payload `<instance>_stats`: the counters of one dds_bridge instance (plugins/dds_bridge),
// one entry per bridged topic, in the order of its configuration (publish entries first).
// Counts are totals since the bridge was configured.
#pragma once

#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct BridgeTopicStats {
  static constexpr std::uint32_t kTopicCapacity = 96;
  enum Direction : std::uint8_t { publish = 0, subscribe = 1 };

  char topic[kTopicCapacity] = {};  // DDS topic name ("rt/…"), NUL-terminated
  std::uint8_t direction = publish;
  std::uint8_t stale = 0;           // subscribe: 1 while its publisher is lost, late, or not heard yet
                                    // (a queue topic: while no publisher of it is alive)
  std::uint16_t matched = 0;        // remote endpoints matched now
  std::uint8_t queue = 0;           // 1: a queue port (events, each delivered once), 0: a latest port
  std::uint8_t reserved[3] = {};
  std::uint64_t samples = 0;        // publish: samples written to DDS; subscribe: valid samples taken
  std::uint64_t port_writes = 0;    // subscribe: values written into the port
  std::uint64_t overwritten = 0;    // a newer value came before the previous one went on (latest semantics)
  std::uint64_t lost = 0;           // subscribe: DDS sample_lost; publish: dds_write failures (a queue
                                    // topic also: events written while no subscriber was matched)
  std::uint64_t rejected = 0;       // subscribe: DDS sample_rejected (resource limits)
  std::uint64_t malformed = 0;      // subscribe: dropped by the bridge's checks (non-finite, out of range)
  std::uint64_t oversized = 0;      // subscribe: dropped, more entries than the payload holds
  std::uint64_t undecodable = 0;    // subscribe: dropped by Cyclone's deserializer (counted from its log)
  std::uint64_t deadline_missed = 0;   // subscribe: requested deadline missed
  std::uint64_t liveliness_lost = 0;   // subscribe: a matched publisher stopped being alive
  std::uint64_t incompatible_qos = 0;  // a remote endpoint of this topic refused for its QoS
  std::uint64_t queue_full = 0;        // queue topics: events dropped because a queue on the way was full
};

struct BridgeStats {
  static constexpr char kPortType[] = "crease.BridgeStats";
  static constexpr std::uint32_t kPortVersion = 2;  // 2: queue topics (queue, queue_full)
  static constexpr std::uint32_t kCapacity = 16;  // topics per bridge instance

  std::uint32_t count = 0;  // valid entries in topics[0..count)
  std::uint32_t stale = 0;  // subscribed topics stale now
  BridgeTopicStats topics[kCapacity];
};

CREASE_PORT_PAYLOAD_LAYOUT(BridgeTopicStats, 200, 8);
CREASE_PORT_PAYLOAD_LAYOUT(BridgeStats, 3208, 8);

}  // namespace crease
