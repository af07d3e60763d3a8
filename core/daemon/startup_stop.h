// A stop asked for while creased starts. SIGINT and SIGTERM are blocked in every thread from
// main's first line (the main loop takes them with sigtimedwait), so one that arrives during
// start-up stays pending: check_startup_stop(), called between the stages of start-up
// (configuration, each plugin's load and configure, memory lock and prefault, the control
// socket, the loops' start), takes it and throws StartupStopped; creased then unwinds what it
// built (plugins deactivated and unloaded), says so and exits 0 without running a loop. A
// stop is honoured within the longest single stage: one plugin's configure, one prefault.
#pragma once

#include <stdexcept>
#include <string>

namespace crease::daemon {

class StartupStopped : public std::runtime_error {
 public:
  StartupStopped(int signal, const std::string& stage);
  [[nodiscard]] int signal() const noexcept { return signal_; }

 private:
  int signal_;
};

// Throws StartupStopped ("stopped by SIGTERM during start-up, STAGE") when SIGINT or SIGTERM
// is pending for the process, taking it. Never blocks.
void check_startup_stop(const std::string& stage);

}  // namespace crease::daemon
