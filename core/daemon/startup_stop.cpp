#include "core/daemon/startup_stop.h"

#include <signal.h>
#include <time.h>

namespace crease::daemon {

StartupStopped::StartupStopped(int signal, const std::string& stage)
    : std::runtime_error(std::string("stopped by ") + (signal == SIGINT ? "SIGINT" : "SIGTERM") +
                         " during start-up, " + stage),
      signal_(signal) {}

void check_startup_stop(const std::string& stage) {
  sigset_t pending;
  sigemptyset(&pending);
  if (sigpending(&pending) != 0) return;
  if (sigismember(&pending, SIGINT) != 1 && sigismember(&pending, SIGTERM) != 1) return;
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  const timespec now{0, 0};
  const int sig = sigtimedwait(&stop, nullptr, &now);
  throw StartupStopped(sig == SIGINT ? SIGINT : SIGTERM, stage);
}

}  // namespace crease::daemon
