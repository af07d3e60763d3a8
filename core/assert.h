// The three assertion tiers of Crease.
//  - CREASE_DEBUG_ASSERT(cond): checked in debug builds only; for invariants on hot paths.
//  - CREASE_DEMAND(cond, msg): always checked; a failure is a bug in Crease: prints and aborts.
//  - crease::require_input(cond, msg): bad user input at configure time: throws ConfigError.
//    Never call it inside a loop's update.
#pragma once

#include <cassert>
#include <string>

#include "core/errors.h"

namespace crease::detail {
[[noreturn]] void demand_failed(const char* cond, const char* msg, const char* file, int line) noexcept;
}

#ifdef NDEBUG
#define CREASE_DEBUG_ASSERT(cond) ((void)0)
#else
#define CREASE_DEBUG_ASSERT(cond) assert(cond)
#endif

#define CREASE_DEMAND(cond, msg) \
  ((cond) ? (void)0 : ::crease::detail::demand_failed(#cond, (msg), __FILE__, __LINE__))

namespace crease {
inline void require_input(bool cond, const std::string& message) {
  if (!cond) throw ConfigError(message);
}
}  // namespace crease
