// A simulated serial link over a Unix-domain stream socket at a path: the simulated device
// listens (UnixLinkListener), the host connects (connect_unix_link) and both ends use the fd
// as they would a tty's (SerialLink, FdSerialIo: raw bytes, COBS/CRC frames, non-blocking).
// Why not a pty: the bytes written to a pty's master reach its slave only when the kernel's
// flush work (an ordinary SCHED_OTHER kworker) runs, and a read of the slave waits for it;
// on a machine whose real-time threads hold the CPUs that work waited 443 ms
// (config.sim_sequence, the taxels a link fault) while the writer and the reader were on
// time. A socket's write wakes the reader itself, so the link is as real-time as its two
// threads. A real sensor stays a tty (SerialPort).
// Non-RT: construction, connect; UnixLinkListener::accept_rt and the fds' I/O are RT-safe
// (non-blocking system calls, no allocation).
#pragma once

#include <string>

namespace crease::drivers {

// True if PATH is (or a symlink at PATH names) a Unix-domain socket.
[[nodiscard]] bool is_unix_socket(const std::string& path) noexcept;

// Connects to the listener at PATH: a non-blocking, close-on-exec stream socket the caller
// owns. Throws std::runtime_error naming PATH.
[[nodiscard]] int connect_unix_link(const std::string& path);

class UnixLinkListener {
 public:
  // Listens at PATH. Something live there (a listening socket, or a symlink to an existing
  // file: another robot's link) is refused; a dead socket or a dangling symlink is replaced.
  // Throws std::runtime_error naming PATH.
  explicit UnixLinkListener(const std::string& path);
  ~UnixLinkListener();  // closes the listener and removes PATH
  UnixLinkListener(const UnixLinkListener&) = delete;
  UnixLinkListener& operator=(const UnixLinkListener&) = delete;

  // A connection waiting to be accepted: its fd (non-blocking, close-on-exec; the caller
  // closes it), or -1. RT-safe.
  [[nodiscard]] int accept_rt() noexcept;
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

// Whether the peer of the connected socket FD has closed its end (or the socket failed).
// RT-safe (poll with no wait).
[[nodiscard]] bool unix_link_hung_up(int fd) noexcept;

}  // namespace crease::drivers
