// SerialIo: the byte link a non-real-time reader thread serves (drivers/host/tactile_reader.h):
// wait for bytes, read what is waiting, write a frame, and be woken to stop. FdSerialIo is a
// tty (a SerialPort's fd, or a pty) waited on with poll(); a test gives its own, e.g. one whose
// reads block until the test lets them go. Nothing here is for a loop's update: every call may
// block or make a syscall.
#pragma once

#include <cstdint>
#include <span>

namespace crease::drivers {

class SerialIo {
 public:
  virtual ~SerialIo() = default;
  // Waits until bytes are waiting, timeout_ms passed or wake() was called, then reads what is
  // waiting into buf. Bytes read (0: none, timed out or woken), or -errno (the link is gone:
  // the caller waits and tries again).
  virtual long read_wait(std::span<std::uint8_t> buf, int timeout_ms) = 0;
  // Bytes written (fewer than asked when the link's buffer is full), or -errno.
  virtual long write(std::span<const std::uint8_t> bytes) = 0;
  // Any thread: makes a read_wait in progress (or the next one) return promptly.
  virtual void wake() noexcept = 0;
};

// A non-blocking tty fd (or a Unix stream socket: unix_link.h; its writes never raise
// SIGPIPE) the caller keeps open (and closes after this is gone); an eventfd wakes the wait.
class FdSerialIo final : public SerialIo {
 public:
  // Throws std::runtime_error when no eventfd can be made.
  explicit FdSerialIo(int fd);
  ~FdSerialIo() override;
  FdSerialIo(const FdSerialIo&) = delete;
  FdSerialIo& operator=(const FdSerialIo&) = delete;
  long read_wait(std::span<std::uint8_t> buf, int timeout_ms) override;
  long write(std::span<const std::uint8_t> bytes) override;
  void wake() noexcept override;

 private:
  int fd_;
  bool socket_ = false;
  int wake_fd_ = -1;
};

}  // namespace crease::drivers
