// The live Z16 depth stream (v4l2_z16_device.h) against a V4L2 capture node emulated in memory
// (fake_v4l2_node.h), and against the kernel's calls for what this machine has (no camera: a
// missing node, /dev/null).
#include "plugins/cameras/v4l2_z16_device.h"

#include <doctest/doctest.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "fake_v4l2_node.h"

using namespace crease::vision;
using crease::testing::FakeNode;

namespace {

V4l2Z16Device::Config small() {
  V4l2Z16Device::Config c;
  c.path = "/dev/video7";
  c.width = 16;
  c.height = 9;
  return c;
}

bool is_frame(const cv::Mat& d, int n) {
  return FakeNode::is_frame(d, n, 16, 9);
}

}  // namespace

TEST_CASE(
    "a Z16 node streams: each frame copied past the driver's row padding, the ring cycled, the "
    "driver's stamps") {
  FakeNode node;
  node.pad = 32;
  V4l2Z16Device dev(node);
  REQUIRE(dev.open(small()).empty());
  CHECK(dev.is_open());
  CHECK(dev.ring_size() == 4);
  CHECK(dev.bytes_per_line() == 64);
  cv::Mat depth;
  std::int64_t stamp = 0, last = 0;
  const void* data = nullptr;
  for (int n = 0; n < 10; ++n) {  // more frames than buffers: each goes back to the driver
    REQUIRE(dev.grab(depth, stamp, 100) == V4l2Z16Device::Grab::frame);
    CHECK(is_frame(depth, n));
    CHECK(stamp > last);
    last = stamp;
    if (n == 0) data = depth.data;
    CHECK(depth.data == data);  // the image is reused, not reallocated
  }
  CHECK(stamp == 100'000'000'000 + 9 * 33'333'000);
  CHECK(dev.frames() == 10);
  CHECK(node.double_queued == 0);
  dev.close();
  CHECK_FALSE(dev.is_open());
  CHECK(node.streamoffs == 1);
  CHECK(node.munmaps == 4);
  CHECK(node.open_fds == 0);
  dev.close();  // again: nothing
  CHECK(node.open_fds == 0);
}

TEST_CASE(
    "what is not a Z16 capture node is refused, naming the path and the step, and nothing is left "
    "open") {
  struct Case {
    const char* what;
    void (*set)(FakeNode&);
    const char* says;
  };
  const Case cases[] = {
      {"a missing node", [](FakeNode&) {}, "does not open"},
      {"an output node", [](FakeNode& n) { n.caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING; },
       "not a video capture node"},
      {"no streaming", [](FakeNode& n) { n.caps = V4L2_CAP_VIDEO_CAPTURE; }, "does not stream"},
      {"the colour node", [](FakeNode& n) { n.format = V4L2_PIX_FMT_YUYV; },
       "delivers 'YUYV', not 'Z16 '"},
      {"another size", [](FakeNode& n) { n.width = 848; },
       "delivers 848 x 9, not the calibration's 16 x 9"},
      {"one buffer", [](FakeNode& n) { n.buffers = 1; }, "gives 1 buffer(s), fewer than 2"},
      {"no mmap buffers", [](FakeNode& n) { n.reqbufs_fails = true; },
       "gives no memory-mapped buffers"},
  };
  for (const Case& k : cases) {
    CAPTURE(k.what);
    FakeNode node;
    k.set(node);
    V4l2Z16Device dev(node);
    V4l2Z16Device::Config c = small();
    if (std::string(k.what) == "a missing node") c.path = "/dev/video3";
    const std::string e = dev.open(c);
    CHECK(e.find(c.path) == 0);
    CHECK(e.find(k.says) != std::string::npos);
    CHECK(dev.last_error() == e);
    CHECK_FALSE(dev.is_open());
    CHECK(node.open_fds == 0);
    cv::Mat d;
    std::int64_t t = 0;
    CHECK(dev.grab(d, t, 0) == V4l2Z16Device::Grab::failed);
  }
  FakeNode node;
  V4l2Z16Device dev(node);
  V4l2Z16Device::Config c = small();
  c.buffers = 1;
  CHECK(dev.open(c).find("buffers >= 2") != std::string::npos);
}

TEST_CASE(
    "a short or error-flagged buffer is skipped, counted and given back; the frames after it "
    "come") {
  FakeNode node;
  node.short_frames = {2};
  node.error_frames = {4};
  V4l2Z16Device dev(node);
  REQUIRE(dev.open(small()).empty());
  cv::Mat depth;
  std::int64_t stamp = 0;
  std::vector<V4l2Z16Device::Grab> got;
  for (int n = 0; n < 7; ++n) {
    got.push_back(dev.grab(depth, stamp, 100));
    if (got.back() == V4l2Z16Device::Grab::frame) CHECK(is_frame(depth, n));
  }
  using G = V4l2Z16Device::Grab;
  CHECK(got == std::vector<G>{G::frame, G::frame, G::bad_frame, G::frame, G::bad_frame, G::frame,
                              G::frame});
  CHECK(dev.frames() == 5);
  CHECK(dev.bad_frames() == 2);
  CHECK(node.double_queued == 0);
  CHECK(dev.is_open());
}

TEST_CASE(
    "a wait without a frame is a timeout; an unplugged camera fails, closes, and opens again") {
  FakeNode node;
  node.timeouts = 2;
  node.unplug_at = 3;
  V4l2Z16Device dev(node);
  REQUIRE(dev.open(small()).empty());
  cv::Mat depth;
  std::int64_t stamp = 0;
  using G = V4l2Z16Device::Grab;
  CHECK(dev.grab(depth, stamp, 10) == G::timeout);
  CHECK(dev.grab(depth, stamp, 10) == G::timeout);
  for (int n = 0; n < 3; ++n) CHECK(dev.grab(depth, stamp, 10) == G::frame);
  CHECK(dev.grab(depth, stamp, 10) == G::failed);
  CHECK(dev.last_error().find("VIDIOC_DQBUF") != std::string::npos);
  CHECK(dev.last_error().find(std::strerror(ENODEV)) != std::string::npos);
  CHECK_FALSE(dev.is_open());
  CHECK(node.open_fds == 0);
  CHECK(node.munmaps == 4);
  node.unplug_at = -1;  // plugged in again
  REQUIRE(dev.open(small()).empty());
  CHECK(dev.grab(depth, stamp, 10) == G::frame);
  CHECK(is_frame(depth, 3));
  CHECK(dev.frames() == 1);  // counted from the open
}

TEST_CASE(
    "the kernel's calls: a missing node and a node that is no V4L2 device are refused with the "
    "path") {
  V4l2Z16Device dev;  // system_v4l2_io()
  V4l2Z16Device::Config c;
  c.path = "/dev/crease-no-such-video";
  std::string e = dev.open(c);
  CHECK(e.find("/dev/crease-no-such-video: does not open") == 0);
  CHECK_FALSE(dev.is_open());
  c.path = "/dev/null";
  e = dev.open(c);
  CHECK(e.find("/dev/null: is not a V4L2 device (VIDIOC_QUERYCAP)") == 0);
  CHECK_FALSE(dev.is_open());
}
