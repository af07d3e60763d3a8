// Preparing the control socket's file: parent folder, stale sockets, ownership and mode.
#pragma once

#include <optional>
#include <string>
#include <sys/types.h>

namespace crease::control {

// Creates PATH's missing parent folders with mode 0700. @throws ControlError
void ensure_parent_dir(const std::string& path);

// When PATH exists: a socket nobody listens on is removed; a socket someone listens on, or
// any other file, throws ControlError ("already in use" / "not a socket").
void remove_stale_socket(const std::string& path);

// Sets PATH's mode to 0600, or to 0660 with group GROUP. Returns GROUP's gid when set.
// @throws ControlError (unknown group, chown/chmod failure)
std::optional<gid_t> set_socket_permissions(const std::string& path,
                                            const std::optional<std::string>& group);

}  // namespace crease::control
