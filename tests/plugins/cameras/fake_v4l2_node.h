// A V4L2 Z16 capture node emulated in memory for the tests of v4l2_z16_device.h and its users:
// the ioctls of the memory-mapped streaming API, the "driver's" answers set by the test.
#pragma once

#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <deque>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <vector>

#include "plugins/cameras/v4l2_z16_device.h"

namespace crease::testing {

// A Z16 capture node: a ring of buffers the "driver" fills in queue order, frame n's pixel
// (r, c) = n * 1000 + 7 r + c, each row padded with 0xab to bytesperline.
class FakeNode final : public crease::vision::V4l2Io {
 public:
  std::string node_path = "/dev/video7";  // the only path that opens
  // What the driver answers.
  std::uint32_t caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::uint32_t format = V4L2_PIX_FMT_Z16;
  int width = -1, height = -1;  // -1: as asked
  std::uint32_t pad = 0;        // bytes after each row
  int buffers = 0;              // 0: as asked
  bool reqbufs_fails = false;
  std::set<int> short_frames, error_frames;  // frame numbers delivered short / flagged in error
  int unplug_at = -1;                        // DQBUF fails with ENODEV at this frame
  int timeouts = 0;                          // polls that time out before the next frame

  // What it saw.
  int open_fds = 0, munmaps = 0, streamoffs = 0, double_queued = 0;
  int frame = 0;  // the next frame's number

  int open(const char* path, int) override {
    if (std::string(path) != node_path) {
      errno = ENOENT;
      return -1;
    }
    ++open_fds;
    return 7;
  }
  int close(int) override {
    --open_fds;
    return 0;
  }
  void* mmap(std::size_t length, int, off_t offset) override {
    const auto i = static_cast<std::size_t>(offset) / kPage;
    if (i >= ring.size() || length != ring[i].size()) return MAP_FAILED;
    return ring[i].data();
  }
  int munmap(void*, std::size_t) override {
    ++munmaps;
    return 0;
  }
  int poll(int, int) override {
    if (timeouts > 0) {
      --timeouts;
      return 0;
    }
    return queued.empty() ? 0 : 1;
  }
  int ioctl(int, unsigned long request, void* arg) override {
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* c = static_cast<v4l2_capability*>(arg);
        c->capabilities = caps;
        return 0;
      }
      case VIDIOC_S_FMT: {
        auto& p = static_cast<v4l2_format*>(arg)->fmt.pix;
        if (width > 0) p.width = static_cast<std::uint32_t>(width);
        if (height > 0) p.height = static_cast<std::uint32_t>(height);
        p.pixelformat = format;
        p.bytesperline = 2 * p.width + pad;
        w = p.width;
        h = p.height;
        return 0;
      }
      case VIDIOC_S_PARM:
        return 0;
      case VIDIOC_REQBUFS: {
        auto* r = static_cast<v4l2_requestbuffers*>(arg);
        if (reqbufs_fails) {
          errno = EINVAL;
          return -1;
        }
        if (r->count == 0) {
          ring.clear();
          return 0;
        }
        r->count = buffers > 0 ? static_cast<std::uint32_t>(buffers) : r->count;
        ring.assign(r->count, std::vector<unsigned char>((2 * w + pad) * h, 0));
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        b->length = static_cast<std::uint32_t>(ring[b->index].size());
        b->m.offset = b->index * kPage;
        return 0;
      }
      case VIDIOC_QBUF: {
        const auto* b = static_cast<v4l2_buffer*>(arg);
        for (const std::uint32_t q : queued) double_queued += q == b->index ? 1 : 0;
        queued.push_back(b->index);
        return 0;
      }
      case VIDIOC_DQBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (frame == unplug_at) {
          errno = ENODEV;
          return -1;
        }
        if (queued.empty()) {
          errno = EAGAIN;
          return -1;
        }
        b->index = queued.front();
        queued.pop_front();
        fill(ring[b->index], frame);
        b->bytesused = static_cast<std::uint32_t>(ring[b->index].size()) -
                       (short_frames.count(frame) ? 100u : 0u);
        b->flags = error_frames.count(frame) ? V4L2_BUF_FLAG_ERROR : 0;
        b->timestamp.tv_sec = 100 + frame / 30;
        b->timestamp.tv_usec = (frame % 30) * 33333;
        ++frame;
        return 0;
      }
      case VIDIOC_STREAMON:
        return 0;
      case VIDIOC_STREAMOFF:
        ++streamoffs;
        queued.clear();
        return 0;
      default:
        errno = ENOTTY;
        return -1;
    }
  }

  static std::uint16_t pixel(int n, int r, int c) {
    return static_cast<std::uint16_t>(n * 1000 + 7 * r + c);
  }
  // D is frame N as this node delivers it, W x H.
  static bool is_frame(const cv::Mat& d, int n, int w, int h) {
    if (d.type() != CV_16UC1 || d.rows != h || d.cols != w) return false;
    for (int r = 0; r < d.rows; ++r)
      for (int c = 0; c < d.cols; ++c)
        if (d.at<std::uint16_t>(r, c) != pixel(n, r, c)) return false;
    return true;
  }

 private:
  static constexpr std::size_t kPage = 4096;
  void fill(std::vector<unsigned char>& buf, int n) const {
    std::memset(buf.data(), 0xab, buf.size());
    for (std::uint32_t r = 0; r < h; ++r)
      for (std::uint32_t c = 0; c < w; ++c) {
        const std::uint16_t v = pixel(n, static_cast<int>(r), static_cast<int>(c));
        buf[r * (2 * w + pad) + 2 * c] = static_cast<unsigned char>(v & 0xff);  // little-endian
        buf[r * (2 * w + pad) + 2 * c + 1] = static_cast<unsigned char>(v >> 8);
      }
  }
  std::vector<std::vector<unsigned char>> ring;
  std::deque<std::uint32_t> queued;
  std::uint32_t w = 0, h = 0;
};

}  // namespace crease::testing
