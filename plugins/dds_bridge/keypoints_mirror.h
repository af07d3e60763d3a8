// crease::Keypoints against the C structs idlc generates from idl/Keypoints.idl: the field
// lists (checked at build time, see mirror.h) and the copies between them. On the wire the
// key-points are a bounded sequence (only `count` of them travel); in C++ an array and a count.
#pragma once

#include <cstdint>

#include "Keypoints.h"
#include "core/port.h"
#include "core/port_types/keypoints.h"
#include "mirror.h"
#include "sample_check.h"

// Every field of crease::Keypoint, in declaration order (also the order of idl/Keypoints.idl).
#define CREASE_KEYPOINT_FIELDS(FIRST, NEXT)                                                     \
  FIRST(world_mm) NEXT(sheet_mm) NEXT(reproj_error_px) NEXT(marker_id) NEXT(corner) NEXT(face) \
  NEXT(views)
CREASE_DDS_MIRROR(crease::Keypoint, crease_msgs_msg_dds__Keypoint_, CREASE_KEYPOINT_FIELDS)

// The fields of crease::Keypoints besides `count` and `points` (the IDL's `points` sequence).
#define CREASE_KEYPOINTS_HEADER_FIELDS(FIRST, NEXT) FIRST(timestamp_ns) NEXT(frame) NEXT(cameras_ok)
CREASE_DDS_MIRROR_TYPES(crease::Keypoints, crease_msgs_msg_dds__Keypoints_, CREASE_KEYPOINTS_HEADER_FIELDS)

namespace crease::dds_bridge::mirror_keypoints {
static_assert(crease_msgs_msg_Keypoints_Constants_CAPACITY == crease::Keypoints::kCapacity,
              "Keypoints.idl's CAPACITY differs from crease::Keypoints::kCapacity");
static_assert(std::is_same_v<decltype(crease_msgs_msg_dds__Keypoints_::points._buffer),
                             crease_msgs_msg_dds__Keypoint_*>);
static_assert(std::is_same_v<decltype(crease::Keypoints::points), crease::Keypoint[crease::Keypoints::kCapacity]>);
// Never called: each side has exactly the header fields, then the key-points.
inline void count_cpp(const crease::Keypoints& v) {
  [[maybe_unused]] const auto& [CREASE_KEYPOINTS_HEADER_FIELDS(CREASE_DDS_NAME_, CREASE_DDS_COMMA_NAME_), count,
                                points] = v;
}
inline void count_c(const crease_msgs_msg_dds__Keypoints_& v) {
  [[maybe_unused]] const auto& [CREASE_KEYPOINTS_HEADER_FIELDS(CREASE_DDS_NAME_, CREASE_DDS_COMMA_NAME_), points] = v;
}
}  // namespace crease::dds_bridge::mirror_keypoints

namespace crease::dds_bridge {

template <class T>
struct Dds;

template <>
struct Dds<crease::Keypoints> {
  using C = crease_msgs_msg_dds__Keypoints_;
  // The sequence's storage for a sample being written.
  struct Scratch {
    crease_msgs_msg_dds__Keypoint_ points[crease::Keypoints::kCapacity];
  };
  static constexpr const char* kKey = "keypoints";
  static const dds_topic_descriptor_t* descriptor() noexcept { return &crease_msgs_msg_dds__Keypoints__desc; }

  // `src.count` must not exceed kCapacity (a value that left a port never does: all_finite()).
  static void to_dds(const crease::Keypoints& src, C& dst, Scratch& scratch) noexcept {
    CREASE_KEYPOINTS_HEADER_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    lend_copies(dst.points, src.points, src.count, scratch.points,
                [](const auto& s, auto& d) { copy_point(s, d); });
  }
  // A corner over 4 or a face over 1 is malformed; more points than kCapacity oversized.
  static SampleCheck from_dds(const C& src, crease::Keypoints& dst) noexcept {
    CREASE_KEYPOINTS_HEADER_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    const SampleCheck c = take_sequence(
        src.points, dst.points, dst.count,
        [](const auto& p) { return p.corner <= 4 && p.face <= 1; },
        [](const auto& s, auto& d) { copy_point(s, d); });
    if (c != SampleCheck::ok) return c;
    return crease::payload_is_finite(dst) ? SampleCheck::ok : SampleCheck::malformed;
  }

 private:
  template <class D, class S>
  static void copy_point(const S& src, D& dst) noexcept {
    CREASE_KEYPOINT_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
};

}  // namespace crease::dds_bridge
