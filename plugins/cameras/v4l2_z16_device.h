// A live depth camera's Z16 stream through the kernel's V4L2 API (Realsense D4xx cameras expose
// their depth as a V4L2 capture node with pixel format 'Z16 ': 16-bit little-endian counts of
// the device's depth unit, 0 = no depth). Memory-mapped streaming: the driver fills a ring of
// buffers; grab() takes the next filled one (DQBUF), copies it row by row into a CV_16UC1
// image (the driver's rows may be padded: bytesperline) and gives the buffer back (QBUF).
// The system calls go through V4l2Io so that tests can drive every path with a device emulated
// in memory (tests/plugins/cameras/v4l2_z16_device_test.cpp); system_v4l2_io() is the kernel's.
// Not RT code (system calls, allocation on the first frame): run it on a vision worker thread.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace crease::vision {

// The system calls a V4L2 device is driven through. Each returns as its POSIX namesake does
// (-1 and errno set on failure; mmap: MAP_FAILED).
class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  virtual int open(const char* path, int flags) = 0;
  virtual int close(int fd) = 0;
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  // PROT_READ | PROT_WRITE, MAP_SHARED.
  virtual void* mmap(std::size_t length, int fd, off_t offset) = 0;
  virtual int munmap(void* addr, std::size_t length) = 0;
  // POLLIN on FD: > 0 readable, 0 timed out, -1 failed.
  virtual int poll(int fd, int timeout_ms) = 0;
};

// The kernel's (ioctl retried on EINTR).
[[nodiscard]] V4l2Io& system_v4l2_io();

class V4l2Z16Device {
 public:
  struct Config {
    std::string path;  // /dev/videoN: the camera's depth node
    int width = 848;   // pixels (D435 depth: 848 x 480; D405: 848 x 480 or 1280 x 720)
    int height = 480;
    int fps = 30;     // asked for with VIDIOC_S_PARM; a driver without it keeps its own
    int buffers = 4;  // the ring asked for (the driver may give more; fewer than 2: refused)
  };
  enum class Grab {
    frame,      // DEPTH and STAMP_NS hold a new image
    timeout,    // nothing within the wait
    bad_frame,  // a buffer flagged in error or shorter than an image: skipped (counted), requeued
    failed,     // the device failed (unplugged: ENODEV, or a ring call refused): close and reopen
  };

  explicit V4l2Z16Device(V4l2Io& io = system_v4l2_io()) : io_(io) {}
  ~V4l2Z16Device() { close(); }
  V4l2Z16Device(const V4l2Z16Device&) = delete;
  V4l2Z16Device& operator=(const V4l2Z16Device&) = delete;

  // Opens C.path and starts streaming. Empty on success; else why, naming the path and the step
  // (a node that is no capture device, a driver that answers another format or size, a ring it
  // will not give), and the device is closed again.
  [[nodiscard]] std::string open(const Config& c);
  // Stops streaming, unmaps the ring and closes the node (idempotent).
  void close() noexcept;
  [[nodiscard]] bool is_open() const noexcept { return fd_ >= 0; }

  // Waits up to TIMEOUT_MS for the next image. frame: DEPTH is a height x width CV_16UC1
  // (reallocated only when it is not), STAMP_NS the driver's capture time (ns on its clock,
  // CLOCK_MONOTONIC for UVC devices).
  Grab grab(cv::Mat& depth, std::int64_t& stamp_ns, int timeout_ms);

  [[nodiscard]] std::uint64_t frames() const noexcept { return frames_; }
  [[nodiscard]] std::uint64_t bad_frames() const noexcept { return bad_frames_; }
  [[nodiscard]] int ring_size() const noexcept { return static_cast<int>(ring_.size()); }
  [[nodiscard]] std::size_t bytes_per_line() const noexcept { return stride_; }
  [[nodiscard]] bool fps_set() const noexcept { return fps_set_; }  // the driver took Config::fps
  [[nodiscard]] const std::string& last_error() const noexcept { return error_; }

 private:
  struct Mapped {
    void* at = nullptr;
    std::size_t length = 0;
  };
  std::string fail(const std::string& step);  // records errno's text, closes, returns the message

  V4l2Io& io_;
  Config cfg_;
  int fd_ = -1;
  bool streaming_ = false;
  bool fps_set_ = false;
  std::size_t stride_ = 0;  // bytes per row as the driver lays them out
  std::vector<Mapped> ring_;
  std::uint64_t frames_ = 0, bad_frames_ = 0;
  std::string error_;
};

}  // namespace crease::vision
