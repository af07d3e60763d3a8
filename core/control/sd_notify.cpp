#include "core/control/sd_notify.h"

#include <cstdint>
#include <cstdlib>

#include <systemd/sd-daemon.h>

namespace crease::control {
namespace {

bool send(const std::string& state) {
  const char* sock = std::getenv("NOTIFY_SOCKET");
  if (sock == nullptr || sock[0] == '\0') return false;
  return ::sd_notify(0, state.c_str()) > 0;
}

std::string with_status(std::string state, const std::string& status) {
  if (!status.empty()) state += "\nSTATUS=" + status;
  return state;
}

}  // namespace

bool notify_ready(const std::string& status) { return send(with_status("READY=1", status)); }
bool notify_watchdog() { return send("WATCHDOG=1"); }
bool notify_stopping(const std::string& status) { return send(with_status("STOPPING=1", status)); }
bool notify_status(const std::string& status) { return send("STATUS=" + status); }

std::optional<std::chrono::microseconds> watchdog_interval() {
  std::uint64_t usec = 0;
  if (::sd_watchdog_enabled(0, &usec) <= 0 || usec == 0) return std::nullopt;
  return std::chrono::microseconds(static_cast<std::int64_t>(usec));
}

}  // namespace crease::control
