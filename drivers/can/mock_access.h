// Who may use a mock CAN bus. The buses are abstract AF_UNIX sockets, which have no file
// permissions, so both ends check the other's kernel-reported credentials (SO_PEERCRED):
// a broker admits a node, and a node trusts a broker, only if the peer runs as the same
// effective uid, as root, or (when a group is configured) as a member of that group.
// Frames travel through memfd rings that exist only as descriptors: a process reaches them
// only when the broker hands them over after the check (and /proc/PID/fd needs the owner's
// ptrace rights), and they are created mode 0600 besides. Not RT (construction and accept).
#pragma once

#include <sys/types.h>

#include <string>

namespace crease::drivers::mockwire {

struct BusAccess {
  uid_t owner = 0;          // this process's effective uid
  bool has_group = false;   // members of `group` are admitted too
  gid_t group = 0;
  std::string group_name;   // for messages
};

// The policy of this process for a bus: `group_name` names the extra group; empty takes the
// environment variable CREASE_CAN_GROUP, and empty again means owner (and root) only.
// Throws std::invalid_argument naming the group if no such group exists.
BusAccess make_bus_access(const std::string& group_name);

struct PeerCred {
  pid_t pid = 0;
  uid_t uid = 0;
  gid_t gid = 0;
};

// Reads the peer's credentials of a connected AF_UNIX socket into `who` and tells whether
// the policy admits it. False too if the kernel cannot tell (then who.uid is (uid_t)-1).
[[nodiscard]] bool peer_allowed(int fd, const BusAccess& access, PeerCred& who) noexcept;

// "uid U (pid P) is neither the owner uid O[, nor in group G (gid)]", for refusal messages.
std::string describe_refusal(const PeerCred& who, const BusAccess& access);

}  // namespace crease::drivers::mockwire
