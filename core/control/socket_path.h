// Where creased listens and creasectl connects when no --socket is given.
#pragma once

#include <string>
#include <sys/types.h>

namespace crease::control {

// root: /run/crease/creased.sock; others: $XDG_RUNTIME_DIR/crease/creased.sock, or
// /tmp/crease-<uid>/creased.sock when XDG_RUNTIME_DIR is unset or empty.
[[nodiscard]] std::string default_socket_path(uid_t euid, const char* xdg_runtime_dir);
// The same rule for this process (geteuid(), getenv("XDG_RUNTIME_DIR")).
[[nodiscard]] std::string default_socket_path();

}  // namespace crease::control
