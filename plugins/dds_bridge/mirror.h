// Build-time checks between a C++ port payload and the C struct idlc generates from its IDL,
// and the field-by-field copies between the two.
//
// A payload's fields are listed once, as a macro of two macros: FIRST is applied to the first
// field and NEXT to the others, so the same list can also spell a comma-separated list:
//   #define CREASE_HAND_COMMAND_FIELDS(FIRST, NEXT) FIRST(timestamp_ns) NEXT(target_rad) ...
//   CREASE_DDS_MIRROR(crease::HandCommand, crease_msgs_msg_dds__HandCommand_, CREASE_HAND_COMMAND_FIELDS)
// CREASE_DDS_MIRROR fails the build unless both structs have exactly the listed non-static data
// members (a structured binding of as many names counts them), each of the same type on both
// sides (an enum counts as its underlying type; arrays by element type and extent), at the same
// offset, and both structs have the same size. So a field added to the IDL and not to the C++
// struct, or the other way round, or one whose type or order differs, is a compile error.
// CREASE_DDS_MIRROR_TYPES checks only the types of the listed fields (for a struct whose other
// members differ on purpose, such as a sequence against an array and its count).
// Use both at global scope.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "sample_check.h"

namespace crease::dds_bridge {

// The representation a field is compared by: enums as their underlying type, arrays element-wise.
template <class T>
struct Repr {
  using type = T;
};
template <class T>
  requires std::is_enum_v<T>
struct Repr<T> {
  using type = std::underlying_type_t<T>;
};
template <class T, std::size_t N>
struct Repr<T[N]> {
  using type = typename Repr<T>::type[N];
};
template <class A, class B>
inline constexpr bool kSameRepr =
    std::is_same_v<typename Repr<std::remove_cv_t<A>>::type, typename Repr<std::remove_cv_t<B>>::type>;

// Copies one field between the two sides (same representation, checked by the mirror macros).
template <class D, class S>
inline void copy_field(D& dst, const S& src) noexcept {
  static_assert(kSameRepr<D, S>, "mirrored fields differ in type");
  if constexpr (std::is_array_v<D>) {
    std::memcpy(dst, src, sizeof(D));
  } else {
    dst = static_cast<D>(src);
  }
}

// Lends a sequence of the generated C (dds_sequence_*: _maximum, _length, _buffer, _release) the
// first LENGTH elements at BUFFER, which it does not own: dds_write only reads them.
template <class Seq, class E>
inline void lend_sequence(Seq& seq, E* buffer, std::uint32_t length,
                          std::uint32_t maximum) noexcept {
  seq._maximum = maximum;
  seq._length = length;
  seq._buffer = buffer;
  seq._release = false;
}

// A port payload's bounded array out to a sequence: the first COUNT (at most N) elements of SRC
// converted by COPY into SCRATCH, which SEQ then borrows (lend_sequence).
template <class Seq, class S, class E, std::size_t N, class Copy>
inline void lend_copies(Seq& seq, const S (&src)[N], std::uint32_t count, E (&scratch)[N],
                        Copy copy) noexcept {
  const std::uint32_t n = count <= N ? count : static_cast<std::uint32_t>(N);
  for (std::uint32_t i = 0; i < n; ++i) copy(src[i], scratch[i]);
  lend_sequence(seq, scratch, n, static_cast<std::uint32_t>(N));
}

// A received sequence into a port payload's bounded array DST (its length into COUNT): more than
// N elements is oversized, an element VALID refuses malformed; each converted by COPY.
template <class Seq, class D, std::size_t N, class Valid, class Copy>
inline SampleCheck take_sequence(const Seq& seq, D (&dst)[N], std::uint32_t& count, Valid valid,
                                 Copy copy) noexcept {
  if (seq._length > N) return SampleCheck::oversized;
  count = seq._length;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!valid(seq._buffer[i])) return SampleCheck::malformed;
    copy(seq._buffer[i], dst[i]);
  }
  return SampleCheck::ok;
}

}  // namespace crease::dds_bridge

#define CREASE_DDS_NAME_(f) f
#define CREASE_DDS_COMMA_NAME_(f) , f
#define CREASE_DDS_SAME_TYPE_(f)                                                        \
  static_assert(::crease::dds_bridge::kSameRepr<decltype(CppT::f), decltype(CT::f)>,    \
                "IDL and C++ struct differ in the type of field '" #f "'");
#define CREASE_DDS_SAME_PLACE_(f)                                                       \
  CREASE_DDS_SAME_TYPE_(f)                                                              \
  static_assert(offsetof(CppT, f) == offsetof(CT, f),                                   \
                "IDL and C++ struct differ in the offset of field '" #f "' (order)");
// Copies field f from `src` to `dst` (both in scope where the list is expanded).
#define CREASE_DDS_COPY_(f) ::crease::dds_bridge::copy_field(dst.f, src.f);

#define CREASE_DDS_MIRROR_TYPES(Cpp, C, FIELDS) \
  namespace crease::dds_bridge::mirror_types_##C { \
  using CppT = Cpp;                              \
  using CT = C;                                  \
  FIELDS(CREASE_DDS_SAME_TYPE_, CREASE_DDS_SAME_TYPE_) \
  }

#define CREASE_DDS_MIRROR(Cpp, C, FIELDS)                                                    \
  namespace crease::dds_bridge::mirror_##C {                                                 \
  using CppT = Cpp;                                                                          \
  using CT = C;                                                                              \
  static_assert(std::is_standard_layout_v<CppT> && std::is_standard_layout_v<CT>);           \
  static_assert(sizeof(CppT) == sizeof(CT), "IDL and C++ struct differ in size");            \
  FIELDS(CREASE_DDS_SAME_PLACE_, CREASE_DDS_SAME_PLACE_)                                     \
  /* Never called: compiling them checks that each side has exactly the listed members. */  \
  inline void count_cpp(const CppT& v) {                                                     \
    [[maybe_unused]] const auto& [FIELDS(CREASE_DDS_NAME_, CREASE_DDS_COMMA_NAME_)] = v;     \
  }                                                                                          \
  inline void count_c(const CT& v) {                                                         \
    [[maybe_unused]] const auto& [FIELDS(CREASE_DDS_NAME_, CREASE_DDS_COMMA_NAME_)] = v;     \
  }                                                                                          \
  }
