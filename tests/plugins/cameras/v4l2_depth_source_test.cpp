// Live RGB-D cameras (v4l2_depth_source.h): a depth node emulated in memory (fake_v4l2_node.h)
// beside a colour "node" that is an image sequence (OpenCV's image reader, as camera_v4l2's
// tests): both images of a frame in the RGB-D channel's order, the driver's stamp, a colour image
// of the wrong size, an unplugged depth node brought back, and the configure errors.
#include "plugins/cameras/v4l2_depth_source.h"

#include <doctest/doctest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "core/errors.h"
#include "fake_v4l2_node.h"

using namespace crease::vision;
using crease::testing::FakeNode;
namespace fs = std::filesystem;

namespace {

// DIR/NNNNNN.png: FRAMES uniform BGR images of W x H; the pattern OpenCV's image reader opens.
std::string colour_sequence(const std::string& name, int frames, int w, int h) {
  const fs::path dir =
      fs::temp_directory_path() / ("crease_v4l2_depth_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  const cv::Mat im(h, w, CV_8UC3, cv::Scalar(40, 120, 200));
  char file[32];
  for (int i = 0; i < frames; ++i) {
    std::snprintf(file, sizeof file, "%06d.png", i);
    REQUIRE(cv::imwrite((dir / file).string(), im));
  }
  return (dir / "%06d.png").string();
}

DepthCamera d405(int w = 16, int h = 9) {
  DepthCamera c;
  c.camera = look_at_camera("d405", w, h, 20, {0, 0, 300}, {0, 0, 0});
  c.depth_unit_mm = 0.1;
  return c;
}

bool is_depth_frame(const cv::Mat& d, int n) {
  return FakeNode::is_frame(d, n, 16, 9);
}

}  // namespace

TEST_CASE(
    "a live RGB-D camera: its depth and colour images in the channel's order, stamped by the "
    "driver") {
  FakeNode node;
  V4l2DepthSource src({d405()}, {"/dev/video7"}, {colour_sequence("ok", 5, 16, 9)}, {}, 50, node);
  CHECK(src.failed().empty());
  CHECK(src.depth_units_mm() == std::vector<double>{0.1});
  CHECK(src.channel_images() == depth_channel_specs(src.cameras()));
  Frame f;
  for (int n = 0; n < 3; ++n) {
    REQUIRE(src.grab(f));
    REQUIRE(f.images.size() == 2);
    CHECK(is_depth_frame(f.images[0], n));
    CHECK(f.images[1].type() == CV_8UC3);
    CHECK(f.images[1].size() == cv::Size(16, 9));
    CHECK(f.images[1].at<cv::Vec3b>(4, 8) == cv::Vec3b(40, 120, 200));
    CHECK(f.timestamp_ns == 100'000'000'000 + n * 33'333'000);
    CHECK(f.index == static_cast<std::uint64_t>(n));
    CHECK(f.poses.empty());  // fixed cameras
    CHECK(src.dark_mask() == 0);
  }
  src.cancel();
  CHECK_FALSE(src.grab(f));
}

TEST_CASE(
    "a colour image of another size leaves the camera's images empty, counted; the camera stays "
    "open") {
  FakeNode node;
  V4l2DepthSource src({d405()}, {"/dev/video7"}, {colour_sequence("big", 3, 32, 18)}, {}, 50, node);
  Frame f;
  REQUIRE(src.grab(f));
  CHECK(f.images[0].empty());
  CHECK(f.images[1].empty());
  CHECK(src.dark_mask() == 1);
  CHECK(src.wrong_colour() == 1);
  CHECK(node.open_fds == 1);
}

TEST_CASE(
    "an unplugged depth node darkens its camera; it is reopened after the back-off and delivers "
    "again") {
  FakeNode node;
  node.unplug_at = 2;
  ReconnectPolicy retry;
  retry.initial_s = 0.02;
  retry.max_s = 0.02;
  V4l2DepthSource src({d405()}, {"/dev/video7"}, {colour_sequence("plug", 20, 16, 9)}, retry, 50,
                      node);
  Frame f;
  REQUIRE(src.grab(f));
  REQUIRE(src.grab(f));
  CHECK(src.dark_mask() == 0);
  REQUIRE(src.grab(f));  // frame 2: ENODEV
  CHECK(src.dark_mask() == 1);
  CHECK(f.images[0].empty());
  CHECK(node.open_fds == 0);
  node.unplug_at = -1;
  REQUIRE(src.grab(f));  // within the back-off: still dark, not retried
  CHECK(src.dark_mask() == 1);
  CHECK(src.reconnects() == 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  REQUIRE(src.grab(f));
  CHECK(src.reconnects() == 1);
  CHECK(src.dark_mask() == 0);
  CHECK(is_depth_frame(f.images[0], 2));
  // A timeout is a missed depth image, not a failure: the camera stays open.
  node.timeouts = 1;
  REQUIRE(src.grab(f));
  CHECK(src.missed_depth() == 1);
  CHECK(src.dark_mask() == 1);
  CHECK(node.open_fds == 1);
}

TEST_CASE(
    "camera_depth_v4l2's sources: what does not open is listed with why; bad set-ups are configure "
    "errors") {
  FakeNode node;
  V4l2DepthSource src({d405(), d405()}, {"/dev/video7", "/dev/video9"},
                      {colour_sequence("a", 2, 16, 9), colour_sequence("b", 2, 16, 9)}, {}, 50,
                      node);
  REQUIRE(src.failed().size() == 1);
  CHECK(src.failed()[0].find("/dev/video9: does not open") == 0);
  CHECK(src.dark_mask() == 2);
  Frame f;
  REQUIRE(src.grab(f));
  CHECK(f.images.size() == 4);
  CHECK(is_depth_frame(f.images[0], 0));
  CHECK(f.images[2].empty());
  CHECK(f.images[3].empty());

  const std::string colour = colour_sequence("c", 1, 16, 9);
  CHECK_THROWS_AS(V4l2DepthSource({d405()}, {}, {colour}, {}, 50, node), crease::ConfigError);
  CHECK_THROWS_AS(V4l2DepthSource({d405()}, {"/dev/video7"}, {}, {}, 50, node),
                  crease::ConfigError);
  CHECK_THROWS_AS(V4l2DepthSource({d405()}, {"/dev/video7"}, {colour}, {}, 0, node),
                  crease::ConfigError);
  DepthCamera wrist = d405();
  wrist.mount = CameraMount{};
  try {
    V4l2DepthSource carried({wrist}, {"/dev/video7"}, {colour}, {}, 50, node);
    FAIL("a carried camera was taken");
  } catch (const crease::ConfigError& e) {
    CHECK(std::string(e.what()).find("carried by the robot") != std::string::npos);
  }
}
