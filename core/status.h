// The outcome of one plugin update, ordered by severity (Drake's EventStatus idea).
#pragma once

#include <cstdint>

namespace crease {

// The numbers are the plugin ABI's (core/abi.h; 3 is the adapter's "threw"): never renumber.
enum class Status : std::int32_t {
  ok = 0,        // did its work
  degraded = 1,  // did what it could; outputs valid but of lower quality (e.g. stale inputs)
  fault = 2,     // cannot go on: the host deactivates it and drives its outputs safe
  // A driver whose device is gone (silent past its timeout, bus-off, an emergency): the plugin
  // itself is sound, has commanded the device's safe state and stays scheduled to notice the
  // device's return. The host counts it as a device fault (status, stats, the report) and shows
  // the instance's health as `fault` until it reports ok or degraded again.
  device_fault = 4,
};

[[nodiscard]] constexpr const char* to_string(Status s) noexcept {
  switch (s) {
    case Status::ok: return "ok";
    case Status::degraded: return "degraded";
    case Status::fault: return "fault";
    case Status::device_fault: return "device_fault";
  }
  return "unknown";
}

// Severity rank: ok < degraded < device_fault < fault.
[[nodiscard]] constexpr int severity(Status s) noexcept {
  switch (s) {
    case Status::ok: return 0;
    case Status::degraded: return 1;
    case Status::device_fault: return 2;
    case Status::fault: return 3;
  }
  return 3;
}

// The worse of two statuses.
[[nodiscard]] constexpr Status worst(Status a, Status b) noexcept { return severity(a) >= severity(b) ? a : b; }

}  // namespace crease
