// The three assertion tiers of Crease (DESIGN.md, "Errors"), and which one a check belongs to:
//  - CREASE_DEBUG_ASSERT(cond): an invariant on a hot or real-time path, checked in debug
//    builds only (nothing in release: the RT rules allow no branch to a failure path there).
//  - CREASE_DEMAND(cond, msg): a promise between two pieces of Crease (a precondition its
//    caller guarantees, an invariant of a data structure) is broken: a bug in Crease. Always
//    checked; prints the place and the reason, aborts. Never for something a user, a file or
//    a device can cause.
//  - require_input(cond, ...): bad user input at configure time (configuration, parameters,
//    calibration, layout and recording files, control requests, what a plugin library
//    declares): throws ConfigError naming the file, line and key. Params::fail and
//    config::error_at are this tier with the place filled in from the YAML node. Never inside
//    a loop's update (there: status values and counters).
// A failure of the environment at configure time (a file that cannot be written, a device that
// does not open) is a crease::Error naming the path and the reason; a plugin attributes it to
// the parameter that named the path (Params::fail).
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
// `message` already names the file, line and key (or the request, or the channel).
inline void require_input(bool cond, const std::string& message) {
  if (!cond) throw ConfigError(message);
}
// "FILE:LINE:COLUMN: KEY.PATH: reason".
inline void require_input(bool cond, const SourceLoc& at, const std::string& key_path, const std::string& reason) {
  if (!cond) throw ConfigError(at, key_path, reason);
}
}  // namespace crease
