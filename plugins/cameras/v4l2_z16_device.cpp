#include "plugins/cameras/v4l2_z16_device.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cstring>

namespace crease::vision {
namespace {

// Z16 is little-endian: the rows are copied as they come.
static_assert(std::endian::native == std::endian::little, "Z16 rows need swapping on this host");

class SystemIo final : public V4l2Io {
 public:
  int open(const char* path, int flags) override { return ::open(path, flags); }
  int close(int fd) override { return ::close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override {
    int r = 0;
    do {
      r = ::ioctl(fd, request, arg);
    } while (r == -1 && errno == EINTR);
    return r;
  }
  void* mmap(std::size_t length, int fd, off_t offset) override {
    return ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
  }
  int munmap(void* addr, std::size_t length) override { return ::munmap(addr, length); }
  int poll(int fd, int timeout_ms) override {
    pollfd p{fd, POLLIN, 0};
    int r = 0;
    do {
      r = ::poll(&p, 1, timeout_ms);
    } while (r == -1 && errno == EINTR);
    if (r > 0 && (p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0 && (p.revents & POLLIN) == 0) {
      errno = ENODEV;
      return -1;
    }
    return r;
  }
};

std::string fourcc_text(std::uint32_t f) {
  std::string s(4, ' ');
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((f >> (8 * i)) & 0xff);
    s[static_cast<std::size_t>(i)] = (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

}  // namespace

V4l2Io& system_v4l2_io() {
  static SystemIo io;
  return io;
}

std::string V4l2Z16Device::fail(const std::string& step) {
  const int e = errno;
  error_ = cfg_.path + ": " + step + (e != 0 ? std::string(" (") + std::strerror(e) + ")" : "");
  close();
  return error_;
}

std::string V4l2Z16Device::open(const Config& c) {
  close();
  cfg_ = c;
  error_.clear();
  frames_ = bad_frames_ = 0;
  errno = 0;
  if (c.width <= 0 || c.height <= 0 || c.fps <= 0 || c.buffers < 2)
    return fail("width, height and fps must be > 0 and buffers >= 2");
  fd_ = io_.open(c.path.c_str(), O_RDWR | O_NONBLOCK);
  if (fd_ < 0) return fail("does not open");

  v4l2_capability cap{};
  if (io_.ioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0)
    return fail("is not a V4L2 device (VIDIOC_QUERYCAP)");
  const std::uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
  errno = 0;
  if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) return fail("is not a video capture node");
  if ((caps & V4L2_CAP_STREAMING) == 0) return fail("does not stream (no V4L2_CAP_STREAMING)");

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = static_cast<std::uint32_t>(c.width);
  fmt.fmt.pix.height = static_cast<std::uint32_t>(c.height);
  fmt.fmt.pix.pixelformat = V4L2_PIX_FMT_Z16;
  fmt.fmt.pix.field = V4L2_FIELD_ANY;
  if (io_.ioctl(fd_, VIDIOC_S_FMT, &fmt) != 0) return fail("refuses Z16 (VIDIOC_S_FMT)");
  errno = 0;
  // S_FMT answers with what the driver will deliver: another format or size is not ours to read.
  if (fmt.fmt.pix.pixelformat != V4L2_PIX_FMT_Z16)
    return fail("delivers '" + fourcc_text(fmt.fmt.pix.pixelformat) +
                "', not 'Z16 ' (not a depth node?)");
  if (fmt.fmt.pix.width != static_cast<std::uint32_t>(c.width) ||
      fmt.fmt.pix.height != static_cast<std::uint32_t>(c.height))
    return fail("delivers " + std::to_string(fmt.fmt.pix.width) + " x " +
                std::to_string(fmt.fmt.pix.height) + ", not the calibration's " +
                std::to_string(c.width) + " x " + std::to_string(c.height));
  stride_ = std::max<std::size_t>(fmt.fmt.pix.bytesperline, 2 * static_cast<std::size_t>(c.width));

  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  parm.parm.capture.timeperframe.numerator = 1;
  parm.parm.capture.timeperframe.denominator = static_cast<std::uint32_t>(c.fps);
  fps_set_ = io_.ioctl(fd_, VIDIOC_S_PARM, &parm) == 0 &&
             parm.parm.capture.timeperframe.numerator * static_cast<std::uint32_t>(c.fps) ==
                 parm.parm.capture.timeperframe.denominator;

  v4l2_requestbuffers req{};
  req.count = static_cast<std::uint32_t>(c.buffers);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (io_.ioctl(fd_, VIDIOC_REQBUFS, &req) != 0)
    return fail("gives no memory-mapped buffers (VIDIOC_REQBUFS)");
  errno = 0;
  if (req.count < 2) return fail("gives " + std::to_string(req.count) + " buffer(s), fewer than 2");
  ring_.reserve(req.count);
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (io_.ioctl(fd_, VIDIOC_QUERYBUF, &b) != 0)
      return fail("VIDIOC_QUERYBUF " + std::to_string(i));
    void* at = io_.mmap(b.length, fd_, static_cast<off_t>(b.m.offset));
    if (at == MAP_FAILED) return fail("mmap of buffer " + std::to_string(i));
    ring_.push_back({at, b.length});
    if (io_.ioctl(fd_, VIDIOC_QBUF, &b) != 0) return fail("VIDIOC_QBUF " + std::to_string(i));
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io_.ioctl(fd_, VIDIOC_STREAMON, &type) != 0) return fail("VIDIOC_STREAMON");
  streaming_ = true;
  return {};
}

void V4l2Z16Device::close() noexcept {
  if (fd_ < 0) return;
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    (void)io_.ioctl(fd_, VIDIOC_STREAMOFF, &type);
    streaming_ = false;
  }
  for (const Mapped& m : ring_) (void)io_.munmap(m.at, m.length);
  if (!ring_.empty()) {  // hand the ring back so that the next open may ask for another
    v4l2_requestbuffers req{};
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    (void)io_.ioctl(fd_, VIDIOC_REQBUFS, &req);
  }
  ring_.clear();
  (void)io_.close(fd_);
  fd_ = -1;
}

V4l2Z16Device::Grab V4l2Z16Device::grab(cv::Mat& depth, std::int64_t& stamp_ns, int timeout_ms) {
  if (fd_ < 0) return Grab::failed;
  const int ready = io_.poll(fd_, timeout_ms);
  if (ready == 0) return Grab::timeout;
  if (ready < 0) {
    fail("poll");
    return Grab::failed;
  }
  v4l2_buffer b{};
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_MMAP;
  if (io_.ioctl(fd_, VIDIOC_DQBUF, &b) != 0) {
    if (errno == EAGAIN) return Grab::timeout;  // readable, but the buffer went to no one
    fail("VIDIOC_DQBUF");
    return Grab::failed;
  }
  const auto w = static_cast<std::size_t>(cfg_.width), h = static_cast<std::size_t>(cfg_.height);
  const std::size_t need = stride_ * (h - 1) + 2 * w;
  Grab out = Grab::bad_frame;
  if (b.index < ring_.size() && (b.flags & V4L2_BUF_FLAG_ERROR) == 0 && b.bytesused >= need &&
      ring_[b.index].length >= need) {
    if (depth.rows != cfg_.height || depth.cols != cfg_.width || depth.type() != CV_16UC1)
      depth.create(cfg_.height, cfg_.width, CV_16UC1);
    const auto* src = static_cast<const unsigned char*>(ring_[b.index].at);
    for (std::size_t r = 0; r < h; ++r)
      std::memcpy(depth.ptr(static_cast<int>(r)), src + r * stride_, 2 * w);
    stamp_ns = static_cast<std::int64_t>(b.timestamp.tv_sec) * 1'000'000'000 +
               static_cast<std::int64_t>(b.timestamp.tv_usec) * 1000;
    ++frames_;
    out = Grab::frame;
  } else {
    ++bad_frames_;
  }
  if (b.index < ring_.size() && io_.ioctl(fd_, VIDIOC_QBUF, &b) != 0) {
    fail("VIDIOC_QBUF");
    return Grab::failed;
  }
  return out;
}

}  // namespace crease::vision
