// crease::ArmState and crease::ArmCommand against the C structs idlc generates from
// idl/ArmState.idl and idl/ArmCommand.idl: the field lists (checked at build time, see
// mirror.h) and the copies between them.
#pragma once

#include "ArmCommand.h"
#include "ArmState.h"
#include "core/port.h"
#include "core/port_types/arm.h"
#include "mirror.h"
#include "sample_check.h"

// Every field of crease::ArmState, in declaration order (also the order of idl/ArmState.idl).
#define CREASE_ARM_STATE_FIELDS(FIRST, NEXT)                                                             \
  FIRST(timestamp_ns) NEXT(device_time_us) NEXT(valid) NEXT(drive_state) NEXT(error_code) NEXT(position_rad) \
  NEXT(velocity_rad_s) NEXT(fresh) NEXT(health) NEXT(safe_state) NEXT(acked_seq) NEXT(commands_sent)       \
  NEXT(commands_failed)
CREASE_DDS_MIRROR(crease::ArmState, crease_msgs_msg_dds__ArmState_, CREASE_ARM_STATE_FIELDS)

// Every field of crease::ArmCommand, in declaration order.
#define CREASE_ARM_COMMAND_FIELDS(FIRST, NEXT) FIRST(timestamp_ns) NEXT(mode) NEXT(position_rad) NEXT(velocity_rad_s)
CREASE_DDS_MIRROR(crease::ArmCommand, crease_msgs_msg_dds__ArmCommand_, CREASE_ARM_COMMAND_FIELDS)

namespace crease::dds_bridge {

template <class T>
struct Dds;

template <>
struct Dds<crease::ArmState> {
  using C = crease_msgs_msg_dds__ArmState_;
  struct Scratch {};
  static constexpr const char* kKey = "arm_state";
  static const dds_topic_descriptor_t* descriptor() noexcept { return &crease_msgs_msg_dds__ArmState__desc; }
  static void to_dds(const crease::ArmState& src, C& dst, Scratch&) noexcept {
    CREASE_ARM_STATE_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
  static SampleCheck from_dds(const C& src, crease::ArmState& dst) noexcept {
    if (src.health > static_cast<std::uint8_t>(crease::DeviceHealth::fault) || src.valid > 0x7f)
      return SampleCheck::malformed;
    CREASE_ARM_STATE_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    return crease::payload_is_finite(dst) ? SampleCheck::ok : SampleCheck::malformed;
  }
};

template <>
struct Dds<crease::ArmCommand> {
  using C = crease_msgs_msg_dds__ArmCommand_;
  struct Scratch {};
  static constexpr const char* kKey = "arm_command";
  static const dds_topic_descriptor_t* descriptor() noexcept { return &crease_msgs_msg_dds__ArmCommand__desc; }
  static void to_dds(const crease::ArmCommand& src, C& dst, Scratch&) noexcept {
    CREASE_ARM_COMMAND_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
  static SampleCheck from_dds(const C& src, crease::ArmCommand& dst) noexcept {
    if (src.mode > crease::ArmCommand::velocity) return SampleCheck::malformed;
    CREASE_ARM_COMMAND_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    return crease::payload_is_finite(dst) ? SampleCheck::ok : SampleCheck::malformed;
  }
};

}  // namespace crease::dds_bridge
