// crease::SheetCreaseEvent and crease::SheetMemorizeEvent (the sheet model's edits, queue ports)
// against the C structs idlc generates from idl/SheetCreaseEvent.idl and
// idl/SheetMemorizeEvent.idl: the field lists (checked at build time, see mirror.h) and the
// copies between them. An event from the network is refused (malformed) with an unknown op, a
// remove of an id outside 0..31, a non-boolean whole_sheet or a non-finite coordinate.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "SheetCreaseEvent.h"
#include "SheetMemorizeEvent.h"
#include "core/port.h"
#include "core/port_types/sheet_state.h"
#include "mirror.h"
#include "sample_check.h"

// Every field of crease::SheetCreaseEvent, in declaration order (also the order of its IDL).
#define CREASE_SHEET_CREASE_EVENT_FIELDS(FIRST, NEXT) FIRST(timestamp_ns) NEXT(op) NEXT(id) NEXT(a_mm) NEXT(b_mm)
CREASE_DDS_MIRROR(crease::SheetCreaseEvent, crease_msgs_msg_dds__SheetCreaseEvent_, CREASE_SHEET_CREASE_EVENT_FIELDS)

// Every field of crease::SheetMemorizeEvent, in declaration order.
#define CREASE_SHEET_MEMORIZE_EVENT_FIELDS(FIRST, NEXT) \
  FIRST(timestamp_ns) NEXT(whole_sheet) NEXT(min_mm) NEXT(max_mm)
CREASE_DDS_MIRROR(crease::SheetMemorizeEvent, crease_msgs_msg_dds__SheetMemorizeEvent_,
                  CREASE_SHEET_MEMORIZE_EVENT_FIELDS)

namespace crease::dds_bridge {

template <class T>
struct Dds;

namespace detail {
inline bool finite2(const float (&v)[2]) noexcept { return std::isfinite(v[0]) && std::isfinite(v[1]); }
}  // namespace detail

template <>
struct Dds<crease::SheetCreaseEvent> {
  using C = crease_msgs_msg_dds__SheetCreaseEvent_;
  struct Scratch {};
  static constexpr const char* kKey = "sheet_crease";
  static constexpr bool kQueue = true;  // events: a queue port, every sample delivered once
  static const dds_topic_descriptor_t* descriptor() noexcept { return &crease_msgs_msg_dds__SheetCreaseEvent__desc; }
  static void to_dds(const crease::SheetCreaseEvent& src, C& dst, Scratch&) noexcept {
    CREASE_SHEET_CREASE_EVENT_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
  static SampleCheck from_dds(const C& src, crease::SheetCreaseEvent& dst) noexcept {
    using Op = crease::SheetCreaseEvent::Op;
    if (src.op > static_cast<std::uint8_t>(Op::clear)) return SampleCheck::malformed;
    if (src.op == static_cast<std::uint8_t>(Op::remove) &&
        (src.id < 0 || src.id >= static_cast<std::int32_t>(crease::SheetState::kMaxCreases)))
      return SampleCheck::malformed;
    if (!detail::finite2(src.a_mm) || !detail::finite2(src.b_mm)) return SampleCheck::malformed;
    CREASE_SHEET_CREASE_EVENT_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    return SampleCheck::ok;
  }
};

template <>
struct Dds<crease::SheetMemorizeEvent> {
  using C = crease_msgs_msg_dds__SheetMemorizeEvent_;
  struct Scratch {};
  static constexpr const char* kKey = "sheet_memorize";
  static constexpr bool kQueue = true;
  static const dds_topic_descriptor_t* descriptor() noexcept { return &crease_msgs_msg_dds__SheetMemorizeEvent__desc; }
  static void to_dds(const crease::SheetMemorizeEvent& src, C& dst, Scratch&) noexcept {
    CREASE_SHEET_MEMORIZE_EVENT_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
  }
  static SampleCheck from_dds(const C& src, crease::SheetMemorizeEvent& dst) noexcept {
    std::uint8_t whole = 0;  // the byte as it came: a bool other than 0 or 1 is not one
    static_assert(sizeof(src.whole_sheet) == 1);
    std::memcpy(&whole, &src.whole_sheet, 1);
    if (whole > 1) return SampleCheck::malformed;
    if (!detail::finite2(src.min_mm) || !detail::finite2(src.max_mm)) return SampleCheck::malformed;
    CREASE_SHEET_MEMORIZE_EVENT_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    return SampleCheck::ok;
  }
};

}  // namespace crease::dds_bridge
