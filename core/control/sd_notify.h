// systemd service notifications (libsystemd's sd_notify) for creased under Type=notify.
// Every call is a no-op returning false when NOTIFY_SOCKET is unset (not started by systemd).
// Non-RT: call from the main thread (or any non-RT thread), never from a loop.
#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace crease::control {

// READY=1 (+ STATUS= when given): configuration validated, loops running, socket listening.
bool notify_ready(const std::string& status = {});
// WATCHDOG=1: call at least every watchdog_interval() / 2 while healthy.
bool notify_watchdog();
// STOPPING=1 (+ STATUS=): shutdown has begun.
bool notify_stopping(const std::string& status = {});
// STATUS=<text>: one line shown by `systemctl status`.
bool notify_status(const std::string& status);

// WatchdogSec= of the unit (from WATCHDOG_USEC/WATCHDOG_PID), or std::nullopt when the
// watchdog is off for this process.
[[nodiscard]] std::optional<std::chrono::microseconds> watchdog_interval();

}  // namespace crease::control
