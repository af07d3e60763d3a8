// The camera_v4l2 plugin in a real loop on image-sequence "devices": a camera missing at start
// joins the frame set once it appears, one that goes away is dark and comes back; the status is
// degraded while any camera is dark and ok while all deliver. Label `concurrency` too: under
// ThreadSanitizer the loop thread's update runs against the capture worker (OpenCV kept on our
// threads by own_threads_only).
#include <doctest/doctest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "plugins/camera_rig/camera_model.h"
#include "support/opencv_threads.h"
#include "support/host_poll.h"

using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {
fs::path tmp(const std::string& name) {
  const auto dir =
      fs::temp_directory_path() / ("crease_camera_v4l2_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  return dir;
}

// DIR/NNNNNN.png: an image sequence of `frames` uniform 64x48 grey images.
void write_sequence(const fs::path& dir, int frames, int grey) {
  fs::create_directories(dir);
  const cv::Mat im(48, 64, CV_8UC1, cv::Scalar(grey));
  char name[32];
  for (int i = 0; i < frames; ++i) {
    std::snprintf(name, sizeof name, "%06d.png", i);
    REQUIRE(cv::imwrite((dir / name).string(), im));
  }
}

struct Loop {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  Loop() { host.add_loop({"cams", 50.0, 0, -1}); }
  crease::CameraFrames frames() {
    crease::CameraFrames f{};
    const auto* ch = host.ports().find_latest("frames");
    REQUIRE(ch != nullptr);
    ch->read(&f, 0);
    return f;
  }
  const crease::PluginStats& stats() {
    for (const auto& i : host.instances())
      if (i.name == "cameras") return *i.stats;
    FAIL("no instance 'cameras'");
    throw 0;
  }
  template <class P>
  bool wait_for(P pred) {
    return crease::testing::poll_until(host, pred, std::chrono::seconds(30), std::chrono::milliseconds(5));
  }
  // Waits for `cycles` more updates; true when none of them was degraded.
  bool ok_for(std::uint64_t cycles) {
    const std::uint64_t degraded = stats().degraded.load(), updates = stats().updates.load();
    REQUIRE(wait_for([&] { return stats().updates.load() >= updates + cycles; }));
    return stats().degraded.load() == degraded;
  }
};
}  // namespace

TEST_CASE("camera_v4l2: a camera that appears late or goes away is dark, then back, status follows") {
  crease::testing::own_threads_only();
  const fs::path dir = tmp("retry");
  fs::create_directories(dir / "cams");
  crease::vision::save_camera(
      crease::vision::look_at_camera("a", 64, 48, 60, {0, -60, 450}, {0, 0, 0}),
      (dir / "cams" / "cam0.yaml").string());
  crease::vision::save_camera(
      crease::vision::look_at_camera("b", 64, 48, 60, {250, 250, 350}, {0, 0, 0}),
      (dir / "cams" / "cam1.yaml").string());
  write_sequence(dir / "a", 1500, 90);  // 30 s at 50 Hz: camera a delivers all along

  Loop loop;
  crease::InstanceSpec s;
  s.name = "cameras";
  s.library = "camera_v4l2";
  s.loop = "cams";
  s.params = crease::Params(
      YAML::Load("{cameras: '" + (dir / "cams").string() + "', devices: ['" +
                 (dir / "a" / "%06d.png").string() + "', '" + (dir / "b" / "%06d.png").string() +
                 "'], stale_cycles: 100000, reconnect_initial_s: 0.02, "
                 "reconnect_max_s: 0.1}"),
      std::string(CREASE_SOURCE_DIR) + "/config/test.yaml", "cameras.params");
  loop.host.add_instance(s);
  loop.host.start();

  // Camera b has no files yet: sets come with camera a only, degraded.
  REQUIRE(loop.wait_for([&] { return loop.frames().sequence > 3 && loop.stats().degraded > 3; }));
  CHECK(loop.frames().valid_mask == 0x1u);
  CHECK_FALSE(loop.ok_for(5));

  write_sequence(dir / "b", 1500, 200);  // the device appears: it joins the frame set
  REQUIRE(loop.wait_for([&] { return loop.frames().valid_mask == 0x3u; }));
  CHECK(loop.ok_for(10));  // ok while both deliver
  CHECK(loop.frames().valid_mask == 0x3u);

  fs::rename(dir / "b", dir / "b.unplugged");  // it goes away: dark, degraded
  REQUIRE(loop.wait_for([&] { return loop.frames().valid_mask == 0x1u; }));
  CHECK_FALSE(loop.ok_for(5));
  fs::rename(dir / "b.unplugged", dir / "b");  // and comes back
  REQUIRE(loop.wait_for([&] { return loop.frames().valid_mask == 0x3u; }));
  CHECK(loop.ok_for(10));
  for (const auto& i : loop.host.instances()) CHECK(i.state == crease::RunState::active);
  CHECK(loop.host.fault_count() == 0);
  loop.host.stop();

  // A back-off that shrinks is refused at configure, naming the key.
  Loop bad;
  s.name = "bad";
  s.loop = "cams";
  s.params = crease::Params(
      YAML::Load("{cameras: '" + (dir / "cams").string() +
                 "', devices: [/dev/video97, /dev/video98], "
                 "reconnect_initial_s: 2, reconnect_max_s: 1}"),
      std::string(CREASE_SOURCE_DIR) + "/config/test.yaml", "bad.params");
  CHECK_THROWS_WITH(bad.host.add_instance(s), doctest::Contains("reconnect_max_s"));
}
