// Pins the layout of a port payload. Payloads may cross processes and machines (a bridge
// between daemons copies their bytes), so their bytes are their interface: standard layout,
// trivially copyable, and a size and alignment written down. A change that moves either must
// raise the payload's kPortVersion and pin the new figures in the same change. Sizes are those
// of the x86-64 / aarch64 LP64 ABI Crease builds for.
#pragma once

#include <type_traits>

#define CREASE_PORT_PAYLOAD_LAYOUT(T, size_bytes, align_bytes)                                       \
  static_assert(std::is_standard_layout_v<T>, #T " must have standard layout: it may cross processes"); \
  static_assert(std::is_trivially_copyable_v<T>, #T " must be trivially copyable: ports copy its bytes"); \
  static_assert(sizeof(T) == (size_bytes), #T " changed size: raise kPortVersion and pin the new size"); \
  static_assert(alignof(T) == (align_bytes), #T " changed alignment: raise kPortVersion and pin it")
