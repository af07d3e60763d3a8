#include "drivers/serial/serial_port.h"

#include <fcntl.h>
#include <pty.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace crease::drivers {
namespace {
void make_raw_nonblocking(int fd, const std::string& what) {
  termios t{};
  if (::tcgetattr(fd, &t) != 0) throw std::runtime_error(what + ": tcgetattr: " + std::strerror(errno));
  ::cfmakeraw(&t);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (::tcsetattr(fd, TCSANOW, &t) != 0) throw std::runtime_error(what + ": tcsetattr: " + std::strerror(errno));
  const int fl = ::fcntl(fd, F_GETFL);
  if (fl < 0 || ::fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0) {
    throw std::runtime_error(what + ": O_NONBLOCK: " + std::strerror(errno));
  }
}
}  // namespace

SerialPort::SerialPort(const SerialConfig& cfg) : device_(cfg.device), port_(io_) {
  using sp = boost::asio::serial_port_base;
  boost::system::error_code ec;
  port_.open(cfg.device, ec);
  if (ec) throw std::runtime_error("serial port '" + cfg.device + "': open: " + ec.message());
  auto set = [&](const auto& opt, const char* name) {
    port_.set_option(opt, ec);
    if (ec) throw std::runtime_error("serial port '" + cfg.device + "': " + name + ": " + ec.message());
  };
  set(sp::baud_rate(cfg.baud), "baud_rate");
  set(sp::character_size(8), "character_size");
  set(sp::parity(sp::parity::none), "parity");
  set(sp::stop_bits(sp::stop_bits::one), "stop_bits");
  set(sp::flow_control(cfg.rts_cts ? sp::flow_control::hardware : sp::flow_control::none), "flow_control");
  make_raw_nonblocking(port_.native_handle(), "serial port '" + cfg.device + "'");
}

long SerialPort::read_some_from_rt(std::span<std::uint8_t> buf) noexcept {
  const ssize_t n = ::read(port_.native_handle(), buf.data(), buf.size());
  if (n >= 0) return n;
  return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : -errno;
}

long SerialPort::write_from_rt(std::span<const std::uint8_t> buf) noexcept {
  const ssize_t n = ::write(port_.native_handle(), buf.data(), buf.size());
  if (n >= 0) return n;
  return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : -errno;
}

PtyPair::PtyPair() {
  char name[256] = {};
  if (::openpty(&master_, &slave_, name, nullptr, nullptr) != 0) {
    throw std::runtime_error(std::string("openpty: ") + std::strerror(errno));
  }
  slave_path_ = name;
  ::fcntl(master_, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave_, F_SETFD, FD_CLOEXEC);
  make_raw_nonblocking(master_, "pty master");
  make_raw_nonblocking(slave_, "pty slave " + slave_path_);
}

PtyPair::~PtyPair() {
  close_slave();
  ::close(master_);
}

void PtyPair::close_slave() noexcept {
  if (slave_ >= 0) ::close(slave_);
  slave_ = -1;
}

SerialLink::SerialLink(int fd) noexcept : fd_(fd) {
  struct stat st{};
  socket_ = ::fstat(fd, &st) == 0 && S_ISSOCK(st.st_mode);
}

long SerialLink::put(const std::uint8_t* bytes, std::size_t n) noexcept {
  return socket_ ? ::send(fd_, bytes, n, MSG_NOSIGNAL | MSG_DONTWAIT) : ::write(fd_, bytes, n);
}

bool SerialLink::send_from_rt(std::uint8_t type, std::span<const std::uint8_t> payload) noexcept {
  const std::size_t n = serial_encode(seq_, type, payload, tx_);
  if (n == 0) return false;
  ++seq_;
  const long w = put(tx_, n);
  if (w != static_cast<long>(n)) {
    ++tx_stats_.tx_short;
    if (w > 0) {
      const std::uint8_t zero = 0;  // terminate the partial frame so the peer drops it
      (void)put(&zero, 1);
    }
    return false;
  }
  ++tx_stats_.tx_frames;
  return true;
}

bool SerialLink::poll_from_rt(SerialFrame& out) noexcept {
  for (;;) {
    if (rx_pos_ < rx_len_) {
      bool got = false;
      rx_pos_ += deframer_.feed({rx_ + rx_pos_, rx_len_ - rx_pos_}, out, &got);
      if (got) return true;
    }
    const ssize_t n = ::read(fd_, rx_, sizeof(rx_));
    if (n <= 0) return false;
    rx_pos_ = 0;
    rx_len_ = static_cast<std::size_t>(n);
  }
}

}  // namespace crease::drivers
