// The outcome of one plugin update, ordered by severity (Drake's EventStatus idea).
#pragma once

#include <cstdint>

namespace crease {

enum class Status : std::int32_t {
  ok = 0,        // did its work
  degraded = 1,  // did what it could; outputs valid but of lower quality (e.g. stale inputs)
  fault = 2,     // cannot go on: the host deactivates it and drives its outputs safe
};

[[nodiscard]] constexpr const char* to_string(Status s) noexcept {
  switch (s) {
    case Status::ok: return "ok";
    case Status::degraded: return "degraded";
    case Status::fault: return "fault";
  }
  return "unknown";
}

// The worse of two statuses.
[[nodiscard]] constexpr Status worst(Status a, Status b) noexcept { return a > b ? a : b; }

}  // namespace crease
