// crease::WorldShapes against the C structs idlc generates from idl/WorldShapes.idl: the field
// lists (checked at build time, see mirror.h) and the copies between them. On the wire the
// shapes are a bounded sequence (only `count` of them travel); in C++ an array and a count.
#pragma once

#include <cstdint>

#include "WorldShapes.h"
#include "core/port.h"
#include "core/port_types/world_shapes.h"
#include "mirror.h"
#include "sample_check.h"

// Every field of crease::WorldShapes::Shape, in declaration order (also idl/WorldShapes.idl's).
#define CREASE_WORLD_SHAPE_FIELDS(FIRST, NEXT)                                            \
  FIRST(kind)                                                                             \
  NEXT(role) NEXT(side) NEXT(reserved) NEXT(radius_mm) NEXT(half_length_mm) NEXT(half_mm) \
      NEXT(position_mm) NEXT(rotation)
CREASE_DDS_MIRROR(crease::WorldShapes::Shape, crease_msgs_msg_dds__WorldShape_,
                  CREASE_WORLD_SHAPE_FIELDS)

// The fields of crease::WorldShapes that travel besides `count` and `shapes` (the IDL's `shapes`
// sequence).
#define CREASE_WORLD_SHAPES_HEADER_FIELDS(FIRST, NEXT) FIRST(timestamp_ns) NEXT(step)
CREASE_DDS_MIRROR_TYPES(crease::WorldShapes, crease_msgs_msg_dds__WorldShapes_,
                        CREASE_WORLD_SHAPES_HEADER_FIELDS)

namespace crease::dds_bridge::mirror_world_shapes {
static_assert(crease_msgs_msg_WorldShapes_Constants_CAPACITY == crease::WorldShapes::kCapacity,
              "WorldShapes.idl's CAPACITY differs from crease::WorldShapes::kCapacity");
static_assert(std::is_same_v<decltype(crease_msgs_msg_dds__WorldShapes_::shapes._buffer),
                             crease_msgs_msg_dds__WorldShape_*>);
static_assert(std::is_same_v<decltype(crease::WorldShapes::shapes),
                             crease::WorldShapes::Shape[crease::WorldShapes::kCapacity]>);
// Never called: the C++ side has the header fields, `count`, its `reserved` word and the shapes;
// the wire the header fields and the shapes. A field added to either fails here.
inline void count_cpp(const crease::WorldShapes& v) {
  [[maybe_unused]] const auto& [timestamp_ns, step, count, reserved, shapes] = v;
}
inline void count_c(const crease_msgs_msg_dds__WorldShapes_& v) {
  [[maybe_unused]] const auto& [timestamp_ns, step, shapes] = v;
}
}  // namespace crease::dds_bridge::mirror_world_shapes

namespace crease::dds_bridge {

template <class T>
struct Dds;

template <>
struct Dds<crease::WorldShapes> {
  using C = crease_msgs_msg_dds__WorldShapes_;
  // The sequence's storage for a sample being written.
  struct Scratch {
    crease_msgs_msg_dds__WorldShape_ shapes[crease::WorldShapes::kCapacity];
  };
  static constexpr const char* kKey = "world_shapes";
  static const dds_topic_descriptor_t* descriptor() noexcept {
    return &crease_msgs_msg_dds__WorldShapes__desc;
  }

  // `src.count` must not exceed kCapacity (a value that left a port never does: all_finite()).
  static void to_dds(const crease::WorldShapes& src, C& dst, Scratch& scratch) noexcept {
    CREASE_WORLD_SHAPES_HEADER_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    lend_copies(dst.shapes, src.shapes, src.count, scratch.shapes,
                [](const auto& s, auto& d) { copy_shape(s, d); });
  }
  // A kind, role or side out of its enum's range is malformed; more shapes than kCapacity
  // oversized.
  static SampleCheck from_dds(const C& src, crease::WorldShapes& dst) noexcept {
    CREASE_WORLD_SHAPES_HEADER_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    dst.reserved = 0;
    const auto valid = [](const auto& s) {
      return s.kind <= static_cast<std::uint8_t>(crease::WorldShapes::Kind::box) &&
             s.role <= static_cast<std::uint8_t>(crease::WorldShapes::Role::arm) && s.side <= 1;
    };
    const SampleCheck c = take_sequence(src.shapes, dst.shapes, dst.count, valid,
                                        [](const auto& s, auto& d) { copy_shape(s, d); });
    if (c != SampleCheck::ok) return c;
    return crease::payload_is_finite(dst) ? SampleCheck::ok : SampleCheck::malformed;
  }

 private:
  template <class D, class S>
  static void copy_shape(const S& src, D& dst) noexcept {
    CREASE_WORLD_SHAPE_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
};

}  // namespace crease::dds_bridge
