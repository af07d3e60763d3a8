// SerialPort: a tty opened through Boost.Asio's serial_port (termios: baud rate, 8 data bits,
// parity, stop bits, flow control), then switched to raw, non-blocking I/O for the RT loop:
// read_some_from_rt / write_from_rt never block. SerialLink adds the COBS/CRC framing.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/serial_port.hpp>
#include <cstdint>
#include <span>
#include <string>

#include "drivers/serial/serial_framing.h"

namespace crease::drivers {

struct SerialConfig {
  std::string device;            // e.g. /dev/ttyUSB0 or a pty slave path
  unsigned baud = 1'000'000;
  bool rts_cts = false;          // hardware flow control
};

class SerialPort {
 public:
  // Opens and configures the port. Throws std::runtime_error naming the device and setting.
  explicit SerialPort(const SerialConfig& cfg);
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Bytes read (0 if none waiting), or -errno. RT-safe.
  [[nodiscard]] long read_some_from_rt(std::span<std::uint8_t> buf) noexcept;
  // Bytes written (possibly fewer than asked when the tty buffer is full), or -errno. RT-safe.
  [[nodiscard]] long write_from_rt(std::span<const std::uint8_t> buf) noexcept;
  [[nodiscard]] int fd() noexcept { return port_.native_handle(); }
  [[nodiscard]] const std::string& device() const noexcept { return device_; }

 private:
  std::string device_;
  boost::asio::io_context io_;
  boost::asio::serial_port port_;
};

// A pseudo-terminal pair (openpty): the master end plays the device, the slave path is opened
// as a SerialPort. Both ends raw. Throws std::runtime_error on failure.
class PtyPair {
 public:
  PtyPair();
  ~PtyPair();
  PtyPair(const PtyPair&) = delete;
  PtyPair& operator=(const PtyPair&) = delete;
  [[nodiscard]] int master_fd() const noexcept { return master_; }
  [[nodiscard]] const std::string& slave_path() const noexcept { return slave_path_; }
  // Keeps the slave open so the master does not see EIO between openings; close to hang up.
  void close_slave() noexcept;

 private:
  int master_ = -1;
  int slave_ = -1;
  std::string slave_path_;
};

struct SerialLinkStats {
  std::uint64_t tx_frames = 0;
  std::uint64_t tx_short = 0;  // frames the tty did not fully accept (dropped, counted)
};

// Framed messages over any byte fd (a SerialPort, a pty master, a Unix stream socket:
// unix_link.h; on a socket, writes never raise SIGPIPE). RT-safe after construction.
class SerialLink {
 public:
  explicit SerialLink(int fd) noexcept;
  // Sends one frame with the next sequence number. False if the tty took only part of it
  // (the receiver then discards the partial frame at the next delimiter).
  bool send_from_rt(std::uint8_t type, std::span<const std::uint8_t> payload) noexcept;
  // Reads what is waiting and returns the next complete valid frame, if any.
  [[nodiscard]] bool poll_from_rt(SerialFrame& out) noexcept;
  [[nodiscard]] const SerialDeframerStats& rx_stats() const noexcept { return deframer_.stats(); }
  [[nodiscard]] const SerialLinkStats& tx_stats() const noexcept { return tx_stats_; }

 private:
  [[nodiscard]] long put(const std::uint8_t* bytes, std::size_t n) noexcept;
  int fd_;
  bool socket_ = false;
  std::uint8_t seq_ = 0;
  SerialDeframer deframer_;
  std::uint8_t rx_[1024] = {};
  std::size_t rx_pos_ = 0, rx_len_ = 0;
  std::uint8_t tx_[kSerialMaxWire] = {};
  SerialLinkStats tx_stats_;
};

}  // namespace crease::drivers
