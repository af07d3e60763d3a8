#include "core/control/socket_file.h"

#include <cerrno>
#include <cstring>
#include <grp.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <vector>

#include "core/control/control_server.h"

namespace crease::control {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
  throw ControlError("control socket " + path + ": " + what + ": " + std::strerror(err));
}

}  // namespace

void ensure_parent_dir(const std::string& path) {
  const auto slash = path.rfind('/');
  if (slash == std::string::npos || slash == 0) return;
  const std::string dir = path.substr(0, slash);
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    pos = dir.find('/', pos + 1);
    const std::string prefix = dir.substr(0, pos);
    if (prefix.empty()) continue;
    if (::mkdir(prefix.c_str(), 0700) != 0 && errno != EEXIST) {
      fail(path, "cannot create folder " + prefix, errno);
    }
  }
  struct stat st {};
  if (::stat(dir.c_str(), &st) != 0) fail(path, "cannot stat folder " + dir, errno);
  if (!S_ISDIR(st.st_mode)) throw ControlError("control socket " + path + ": " + dir + " is not a folder");
}

void remove_stale_socket(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return;
    fail(path, "cannot stat", errno);
  }
  if (!S_ISSOCK(st.st_mode)) {
    throw ControlError("control socket " + path + ": exists and is not a socket; not replacing it");
  }
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof(addr.sun_path)) throw ControlError("control socket " + path + ": path too long");
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) fail(path, "socket()", errno);
  const int rc = ::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr));
  const int err = errno;
  ::close(fd);
  if (rc == 0) {
    throw ControlError("control socket " + path +
                       ": already in use (another creased is listening there)");
  }
  if (err != ECONNREFUSED && err != ENOENT) fail(path, "cannot probe the existing socket", err);
  if (::unlink(path.c_str()) != 0 && errno != ENOENT) fail(path, "cannot remove the stale socket", errno);
}

std::optional<gid_t> set_socket_permissions(const std::string& path,
                                            const std::optional<std::string>& group) {
  if (!group) {
    if (::chmod(path.c_str(), 0600) != 0) fail(path, "chmod 0600", errno);
    return std::nullopt;
  }
  std::vector<char> buf(16384);
  struct group gr {};
  struct group* found = nullptr;
  const int rc = ::getgrnam_r(group->c_str(), &gr, buf.data(), buf.size(), &found);
  if (rc != 0 || found == nullptr) {
    throw ControlError("control socket " + path + ": unknown group '" + *group + "'");
  }
  if (::chown(path.c_str(), static_cast<uid_t>(-1), gr.gr_gid) != 0) {
    fail(path, "chown to group " + *group, errno);
  }
  if (::chmod(path.c_str(), 0660) != 0) fail(path, "chmod 0660", errno);
  return gr.gr_gid;
}

}  // namespace crease::control
