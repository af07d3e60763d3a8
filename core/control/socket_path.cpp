#include "core/control/socket_path.h"

#include <cstdlib>
#include <unistd.h>

namespace crease::control {

std::string default_socket_path(uid_t euid, const char* xdg_runtime_dir) {
  if (euid == 0) return "/run/crease/creased.sock";
  if (xdg_runtime_dir != nullptr && xdg_runtime_dir[0] != '\0') {
    return std::string(xdg_runtime_dir) + "/crease/creased.sock";
  }
  return "/tmp/crease-" + std::to_string(euid) + "/creased.sock";
}

std::string default_socket_path() {
  return default_socket_path(::geteuid(), std::getenv("XDG_RUNTIME_DIR"));
}

}  // namespace crease::control
