#include "drivers/can/mock_access.h"

#include <grp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <vector>

namespace crease::drivers::mockwire {

BusAccess make_bus_access(const std::string& group_name) {
  BusAccess a;
  a.owner = ::geteuid();
  std::string name = group_name;
  if (name.empty()) {
    const char* env = std::getenv("CREASE_CAN_GROUP");
    if (env) name = env;
  }
  if (name.empty()) return a;
  std::vector<char> buf(16384);
  group g{};
  group* found = nullptr;
  const int rc = ::getgrnam_r(name.c_str(), &g, buf.data(), buf.size(), &found);
  if (rc != 0 || !found) {
    throw std::invalid_argument("mock CAN bus access: no group named '" + name + "' (CREASE_CAN_GROUP or the bus's group)");
  }
  a.has_group = true;
  a.group = found->gr_gid;
  a.group_name = name;
  return a;
}

bool peer_allowed(int fd, const BusAccess& access, PeerCred& who) noexcept {
  ucred cred{};
  socklen_t len = sizeof(cred);
  who = PeerCred{};
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) != 0 || len != sizeof(cred)) {
    who.uid = static_cast<uid_t>(-1);
    return false;
  }
  who = {cred.pid, cred.uid, cred.gid};
  if (cred.uid == access.owner || cred.uid == 0) return true;
  if (!access.has_group) return false;
  if (cred.gid == access.group) return true;
  // Supplementary groups of the peer (as they were at connect time).
  gid_t groups[256];
  socklen_t glen = sizeof(groups);
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, groups, &glen) != 0) return false;
  const std::size_t n = glen / sizeof(gid_t);
  return std::find(groups, groups + n, access.group) != groups + n;
}

std::string describe_refusal(const PeerCred& who, const BusAccess& access) {
  if (who.uid == static_cast<uid_t>(-1)) return "the peer's credentials are unknown";
  std::string s = "uid " + std::to_string(who.uid) + " (pid " + std::to_string(who.pid) + ") is neither the owner uid " +
                  std::to_string(access.owner) + " nor root";
  if (access.has_group) s += ", nor in group '" + access.group_name + "' (" + std::to_string(access.group) + ")";
  return s;
}

}  // namespace crease::drivers::mockwire
