// Port payload `tactile`: the newest tactile matrix sample of one hand (5 fingertips x 34
// taxels, seed 000 Section V), with its age, written by the hand_driver plugin.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/hand.h"  // DeviceHealth
#include "core/port_types/payload_layout.h"

namespace crease {

struct Tactile {
  static constexpr char kPortType[] = "crease.Tactile";
  static constexpr std::uint32_t kPortVersion = 2;  // 2: the link's counters
  static constexpr int kFingertips = 5;
  static constexpr int kTaxels = 34;

  std::int64_t timestamp_ns = 0;      // reception time of the sample: the loop's cycle that took it
  std::uint32_t device_time_us = 0;
  std::uint16_t sample_counter = 0;
  std::uint8_t valid = 0;             // bit f: fingertip f delivered data
  std::uint8_t fresh = 0;             // 1: a new sample arrived this cycle
  DeviceHealth health = DeviceHealth::fault;
  std::int64_t age_ns = 0;            // cycle time minus timestamp_ns
  std::uint64_t frames = 0;           // samples taken from the link so far
  std::uint64_t crc_errors = 0;       // frames the link dropped for a bad CRC or bad COBS
  std::uint64_t overruns = 0;         // samples dropped before the loop took them (its reader's queue full)
  float pressure_kpa[kFingertips][kTaxels] = {};

  [[nodiscard]] bool all_finite() const {
    for (const auto& f : pressure_kpa)
      for (float x : f)
        if (!std::isfinite(x)) return false;
    return true;
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(Tactile, 736, 8);

}  // namespace crease
