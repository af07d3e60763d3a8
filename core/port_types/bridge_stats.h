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
  std::uint16_t matched = 0;        // remote endpoints matched now
  std::uint32_t reserved = 0;
  std::uint64_t samples = 0;        // publish: samples written to DDS; subscribe: valid samples taken
  std::uint64_t port_writes = 0;    // subscribe: values written into the port
  std::uint64_t overwritten = 0;    // a newer value came before the previous one went on (latest semantics)
  std::uint64_t lost = 0;           // subscribe: DDS sample_lost; publish: dds_write failures
  std::uint64_t rejected = 0;       // subscribe: DDS sample_rejected (resource limits)
  std::uint64_t malformed = 0;      // subscribe: dropped by the bridge's checks (non-finite, out of range)
  std::uint64_t oversized = 0;      // subscribe: dropped, more entries than the payload holds
  std::uint64_t undecodable = 0;    // subscribe: dropped by Cyclone's deserializer (counted from its log)
  std::uint64_t deadline_missed = 0;   // subscribe: requested deadline missed
  std::uint64_t liveliness_lost = 0;   // subscribe: a matched publisher stopped being alive
  std::uint64_t incompatible_qos = 0;  // a remote endpoint of this topic refused for its QoS
};

struct BridgeStats {
  static constexpr char kPortType[] = "crease.BridgeStats";
  static constexpr std::uint32_t kPortVersion = 1;
  static constexpr std::uint32_t kCapacity = 16;  // topics per bridge instance

  std::uint32_t count = 0;  // valid entries in topics[0..count)
  std::uint32_t stale = 0;  // subscribed topics stale now
  BridgeTopicStats topics[kCapacity];
};

CREASE_PORT_PAYLOAD_LAYOUT(BridgeTopicStats, 192, 8);
CREASE_PORT_PAYLOAD_LAYOUT(BridgeStats, 3080, 8);

}  // namespace crease
