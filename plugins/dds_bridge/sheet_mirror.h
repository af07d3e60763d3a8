// crease::SheetState against the C struct idlc generates from idl/SheetState.idl: the field
// lists (checked at build time, see mirror.h) and the copies between them. On the wire the
// node, crease and strain arrays are bounded sequences of their valid entries only; in C++
// fixed arrays and counts (nodes_u x nodes_v nodes, crease_count creases, link_count links).
#pragma once

#include <cstdint>
#include <cstring>

#include "SheetState.h"
#include "core/port.h"
#include "core/port_types/sheet_state.h"
#include "mirror.h"
#include "sample_check.h"

// The scalar fields of crease::SheetState besides the counts, in declaration order (also the
// order of idl/SheetState.idl, where the counts are the sequences' lengths).
#define CREASE_SHEET_STATE_HEADER_FIELDS(FIRST, NEXT)                                                     \
  FIRST(timestamp_ns) NEXT(step) NEXT(nodes_u) NEXT(nodes_v) NEXT(width_mm) NEXT(height_mm) NEXT(fit_error_mm) \
  NEXT(observations) NEXT(rollbacks)
CREASE_DDS_MIRROR_TYPES(crease::SheetState, crease_msgs_msg_dds__SheetState_, CREASE_SHEET_STATE_HEADER_FIELDS)

namespace crease::dds_bridge::mirror_sheet_state {
using S = crease::SheetState;
using C = crease_msgs_msg_dds__SheetState_;
static_assert(crease_msgs_msg_SheetState_Constants_MAX_NODE_FLOATS == 3 * S::kMaxNodes,
              "SheetState.idl's MAX_NODE_FLOATS differs from 3 x crease::SheetState::kMaxNodes");
static_assert(crease_msgs_msg_SheetState_Constants_MAX_CREASE_FLOATS == 4 * S::kMaxCreases,
              "SheetState.idl's MAX_CREASE_FLOATS differs from 4 x crease::SheetState::kMaxCreases");
static_assert(crease_msgs_msg_SheetState_Constants_MAX_CREASES == S::kMaxCreases,
              "SheetState.idl's MAX_CREASES differs from crease::SheetState::kMaxCreases");
static_assert(crease_msgs_msg_SheetState_Constants_MAX_LINKS == S::kMaxLinks,
              "SheetState.idl's MAX_LINKS differs from crease::SheetState::kMaxLinks");
// Each sequence's element type is the C++ array's.
static_assert(std::is_same_v<decltype(C::position_mm._buffer), float*> &&
              std::is_same_v<decltype(S::position_mm), float[S::kMaxNodes][3]>);
static_assert(std::is_same_v<decltype(C::normal._buffer), float*> &&
              std::is_same_v<decltype(S::normal), float[S::kMaxNodes][3]>);
static_assert(std::is_same_v<decltype(C::crease_mm._buffer), float*> &&
              std::is_same_v<decltype(S::crease_mm), float[S::kMaxCreases][4]>);
static_assert(std::is_same_v<decltype(C::crease_id._buffer), std::int32_t*> &&
              std::is_same_v<decltype(S::crease_id), std::int32_t[S::kMaxCreases]>);
static_assert(std::is_same_v<decltype(C::strain._buffer), float*> &&
              std::is_same_v<decltype(S::strain), float[S::kMaxLinks]>);
// Never called: each side has exactly these members (the C++ counts are the C lengths).
inline void count_cpp(const S& v) {
  [[maybe_unused]] const auto& [timestamp_ns, step, nodes_u, nodes_v, width_mm, height_mm, link_count, crease_count,
                                fit_error_mm, observations, rollbacks, position_mm, normal, crease_mm, crease_id,
                                strain] = v;
}
inline void count_c(const C& v) {
  [[maybe_unused]] const auto& [CREASE_SHEET_STATE_HEADER_FIELDS(CREASE_DDS_NAME_, CREASE_DDS_COMMA_NAME_),
                                position_mm, normal, crease_mm, crease_id, strain] = v;
}
}  // namespace crease::dds_bridge::mirror_sheet_state

namespace crease::dds_bridge {

template <class T>
struct Dds;

template <>
struct Dds<crease::SheetState> {
  using C = crease_msgs_msg_dds__SheetState_;
  struct Scratch {};  // the sequences point into the value being written (stable while dds_write runs)
  static constexpr const char* kKey = "sheet_state";
  static const dds_topic_descriptor_t* descriptor() noexcept { return &crease_msgs_msg_dds__SheetState__desc; }

  // Counts beyond the payload's capacity are clipped (a value that left a port never has them:
  // all_finite()).
  static void to_dds(const crease::SheetState& src, C& dst, Scratch&) noexcept {
    CREASE_SHEET_STATE_HEADER_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    std::uint32_t nodes = static_cast<std::uint32_t>(src.nodes_u) * src.nodes_v;
    if (nodes > crease::SheetState::kMaxNodes) nodes = 0;
    const std::uint32_t creases = src.crease_count <= crease::SheetState::kMaxCreases ? src.crease_count : 0;
    const std::uint32_t links = src.link_count <= crease::SheetState::kMaxLinks ? src.link_count : 0;
    point(dst.position_mm, &src.position_mm[0][0], 3 * nodes);
    point(dst.normal, &src.normal[0][0], 3 * nodes);
    point(dst.crease_mm, &src.crease_mm[0][0], 4 * creases);
    point(dst.crease_id, &src.crease_id[0], creases);
    point(dst.strain, &src.strain[0], links);
  }

  static SampleCheck from_dds(const C& src, crease::SheetState& dst) noexcept {
    const std::uint32_t nodes = static_cast<std::uint32_t>(src.nodes_u) * src.nodes_v;
    if (nodes > crease::SheetState::kMaxNodes || src.crease_id._length > crease::SheetState::kMaxCreases ||
        src.strain._length > crease::SheetState::kMaxLinks || src.position_mm._length > 3 * crease::SheetState::kMaxNodes ||
        src.normal._length > 3 * crease::SheetState::kMaxNodes || src.crease_mm._length > 4 * crease::SheetState::kMaxCreases)
      return SampleCheck::oversized;
    if (src.position_mm._length != 3 * nodes || src.normal._length != 3 * nodes ||
        src.crease_mm._length != 4 * src.crease_id._length)
      return SampleCheck::malformed;
    CREASE_SHEET_STATE_HEADER_FIELDS(CREASE_DDS_COPY_, CREASE_DDS_COPY_)
    dst.crease_count = src.crease_id._length;
    dst.link_count = src.strain._length;
    take(&dst.position_mm[0][0], src.position_mm);
    take(&dst.normal[0][0], src.normal);
    take(&dst.crease_mm[0][0], src.crease_mm);
    take(&dst.crease_id[0], src.crease_id);
    take(&dst.strain[0], src.strain);
    return crease::payload_is_finite(dst) ? SampleCheck::ok : SampleCheck::malformed;
  }

 private:
  template <class Seq, class E>
  static void point(Seq& seq, const E* data, std::uint32_t n) noexcept {
    lend_sequence(seq, const_cast<E*>(data), n, n);  // only read by dds_write
  }
  template <class E, class Seq>
  static void take(E* out, const Seq& seq) noexcept {
    if (seq._length != 0) std::memcpy(out, seq._buffer, seq._length * sizeof(E));
  }
};

}  // namespace crease::dds_bridge
