// crease::HandState and crease::HandCommand against the C structs idlc generates from
// idl/HandState.idl and idl/HandCommand.idl: the field lists (checked at build time, see
// mirror.h) and the copies between them.
#pragma once

#include "HandCommand.h"
#include "HandState.h"
#include "core/port.h"
#include "core/port_types/hand.h"
#include "mirror.h"
#include "sample_check.h"

// Every field of crease::HandState, in declaration order (also the order of idl/HandState.idl).
#define CREASE_HAND_STATE_FIELDS(FIRST, NEXT)                                               \
  FIRST(timestamp_ns) NEXT(device_time_us) NEXT(valid) NEXT(position_rad) NEXT(pressure_kpa) \
  NEXT(pressure_valid) NEXT(fresh) NEXT(health) NEXT(safe_state) NEXT(acked_seq)            \
  NEXT(commands_sent) NEXT(commands_failed)
CREASE_DDS_MIRROR(crease::HandState, crease_msgs_msg_dds__HandState_, CREASE_HAND_STATE_FIELDS)

// Every field of crease::HandCommand, in declaration order.
#define CREASE_HAND_COMMAND_FIELDS(FIRST, NEXT) \
  FIRST(timestamp_ns) NEXT(target_rad) NEXT(stiffness_nm_per_rad) NEXT(enable)
CREASE_DDS_MIRROR(crease::HandCommand, crease_msgs_msg_dds__HandCommand_, CREASE_HAND_COMMAND_FIELDS)

namespace crease::dds_bridge {

template <class T>
struct Dds;

template <>
struct Dds<crease::HandState> {
  using C = crease_msgs_msg_dds__HandState_;
  struct Scratch {};
  static constexpr const char* kKey = "hand_state";
  static const dds_topic_descriptor_t* descriptor() noexcept { return &crease_msgs_msg_dds__HandState__desc; }
  static void to_dds(const crease::HandState& src, C& dst, Scratch&) noexcept {
    CREASE_HAND_STATE_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
  static SampleCheck from_dds(const C& src, crease::HandState& dst) noexcept {
    if (src.health > static_cast<std::uint8_t>(crease::DeviceHealth::fault)) return SampleCheck::malformed;
    CREASE_HAND_STATE_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    return crease::payload_is_finite(dst) ? SampleCheck::ok : SampleCheck::malformed;
  }
};

template <>
struct Dds<crease::HandCommand> {
  using C = crease_msgs_msg_dds__HandCommand_;
  struct Scratch {};
  static constexpr const char* kKey = "hand_command";
  static const dds_topic_descriptor_t* descriptor() noexcept { return &crease_msgs_msg_dds__HandCommand__desc; }
  static void to_dds(const crease::HandCommand& src, C& dst, Scratch&) noexcept {
    CREASE_HAND_COMMAND_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
  static SampleCheck from_dds(const C& src, crease::HandCommand& dst) noexcept {
    if (src.enable > 1) return SampleCheck::malformed;
    CREASE_HAND_COMMAND_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    return crease::payload_is_finite(dst) ? SampleCheck::ok : SampleCheck::malformed;
  }
};

}  // namespace crease::dds_bridge
