#include "plugins/cameras/camera_source.h"
#include "plugins/cameras/replay_source.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <doctest/doctest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"
#include "plugins/sim_world/scene/marker_scene.h"
#include "plugins/sim_world/scene/sim_source.h"
#include "plugins/vision/keypoint_pipeline.h"

using namespace crease::vision;

namespace {
std::string tmp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("crease_vision_src_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  return dir.string();
}

std::vector<crease::Keypoints> run(CameraSource& src, const MarkerLayout& layout, int frames) {
  KeypointPipeline pipe(src.cameras(), layout, DetectorConfig{}, TriangulationConfig{});
  std::vector<crease::Keypoints> out;
  Frame f;
  for (int i = 0; i < frames && src.grab(f); ++i) {
    out.emplace_back();
    pipe.process(f.images, f.timestamp_ns, out.back());
  }
  return out;
}
}  // namespace

TEST_CASE("a recorded sequence replayed twice gives identical key-points") {
#ifdef CREASE_SANITIZER_ADDRESS
  constexpr std::size_t kFrames = 2;  // rendering is slow under the sanitizer
#else
  constexpr std::size_t kFrames = 3;
#endif
  crease::vision::testing::Scene s;
  auto renderer = std::shared_ptr<const ViewRenderer>(std::move(s.renderer));
  const SheetMesh flat = flat_sheet(22, 31, s.layout.sheet_w_mm, s.layout.sheet_h_mm, {0, 0, 0}, 0.1);
  SimSource sim(renderer, [&](std::uint64_t i) { return fold_sheet(flat, s.layout.sheet_h_mm / 2, 0.3 * double(i)); },
                RenderOptions{.seed = 5, .occluders = 1}, 33'333'333);
  const std::string dir = tmp_dir("rec");
  {
    Recorder rec(dir, sim.cameras());
    Frame f;
    for (std::size_t i = 0; i < kFrames; ++i) {
      REQUIRE(sim.grab(f));
      rec.write(f);
    }
  }
  CHECK(std::filesystem::exists(dir + "/cam4/00000" + std::to_string(kFrames - 1) + ".png"));
  CHECK(std::filesystem::exists(dir + "/cam0.yaml"));
  ReplaySource a(dir), b(dir);
  CHECK(a.frames() == kFrames);
  const auto ka = run(a, s.layout, 10), kb = run(b, s.layout, 10);
  REQUIRE(ka.size() == kFrames);
  REQUIRE(kb.size() == kFrames);
  for (std::size_t i = 0; i < kFrames; ++i) {
    // Stamped with each replay's own time, never closer than recorded (a frame the detection
    // made late is stamped when handed out: replay_source_test.cpp).
    if (i > 0) {
      CHECK(ka[i].timestamp_ns - ka[i - 1].timestamp_ns >= 33'333'333);
      CHECK(kb[i].timestamp_ns - kb[i - 1].timestamp_ns >= 33'333'333);
    }
    REQUIRE(ka[i].count == kb[i].count);
    CHECK(ka[i].count > 100);
    CHECK(std::memcmp(ka[i].points, kb[i].points, sizeof(crease::Keypoint) * ka[i].count) == 0);
  }
}

TEST_CASE("a camera whose files stop leaves the others running; bad recordings name the file") {
  crease::vision::testing::Scene s;
  auto renderer = std::shared_ptr<const ViewRenderer>(std::move(s.renderer));
  const SheetMesh flat = flat_sheet(22, 31, s.layout.sheet_w_mm, s.layout.sheet_h_mm, {0, 0, 0}, 0.1);
  SimSource sim(renderer, [&](std::uint64_t) { return flat; }, RenderOptions{}, 10);
  const std::string dir = tmp_dir("gap");
  {
    Recorder rec(dir, sim.cameras());
    Frame f;
    for (int i = 0; i < 2; ++i) {
      REQUIRE(sim.grab(f));
      rec.write(f);
    }
  }
  std::filesystem::remove(dir + "/cam3/000001.png");
  ReplaySource r(dir);
  const auto k = run(r, s.layout, 10);
  REQUIRE(k.size() == 2);
  CHECK(k[0].cameras_ok == 0x1f);
  CHECK(k[1].cameras_ok == 0x17);
  CHECK(k[1].count == 35 * 5);

  std::ofstream(dir + "/timestamps.csv") << "frame,timestamp_ns\n0;12\n";
  CHECK_THROWS_WITH_AS(ReplaySource{dir}, doctest::Contains("timestamps.csv: line 2"), crease::ConfigError);
  CHECK_THROWS_WITH_AS(ReplaySource{tmp_dir("nothing")}, doctest::Contains("cam0.yaml"), crease::ConfigError);
}

namespace {
// An image sequence camera_v4l2 can open: DIR/NNNNNN.png, `frames` uniform grey images.
void write_sequence(const std::filesystem::path& dir, int frames, int grey) {
  std::filesystem::create_directories(dir);
  const cv::Mat im(48, 64, CV_8UC1, cv::Scalar(grey));
  char name[32];
  for (int i = 0; i < frames; ++i) {
    std::snprintf(name, sizeof name, "%06d.png", i);
    REQUIRE(cv::imwrite((dir / name).string(), im));
  }
}

std::vector<Camera> tiny_rig() {
  return {look_at_camera("a", 64, 48, 60, {0, -60, 450}, {0, 0, 0}),
          look_at_camera("b", 64, 48, 60, {250, 250, 350}, {0, 0, 0})};
}

// Grabs (5 ms apart, at most ~3 s) until camera k's image is empty (dark) or not.
bool grab_until(V4l2Source& src, Frame& f, std::size_t k, bool dark) {
  for (int i = 0; i < 600; ++i) {
    REQUIRE(src.grab(f));
    if (f.images[k].empty() == dark) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

constexpr ReconnectPolicy kFastRetry{.initial_s = 0.02, .max_s = 0.08};
}  // namespace

TEST_CASE("camera_v4l2 source: a device missing at start is opened once it appears") {
  const std::filesystem::path dir = tmp_dir("late");
  write_sequence(dir / "a", 60, 90);
  const std::string late = (dir / "b" / "%06d.png").string();
  V4l2Source src(tiny_rig(), {(dir / "a" / "%06d.png").string(), late}, kFastRetry);
  CHECK(src.failed_devices() == std::vector<std::string>{late});
  CHECK(src.dark_mask() == 0x2u);
  Frame f;
  for (int i = 0; i < 5; ++i) {  // several retries pass: still nothing there
    REQUIRE(src.grab(f));
    CHECK_FALSE(f.images[0].empty());
    CHECK(f.images[1].empty());
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  CHECK(src.reconnects(1) == 0);
  write_sequence(dir / "b", 60, 200);
  REQUIRE(grab_until(src, f, 1, false));
  CHECK(f.images[1].at<std::uint8_t>(10, 10) == 200);
  CHECK_FALSE(f.images[0].empty());
  CHECK(src.dark_mask() == 0u);
  CHECK(src.reconnects(1) == 1);
  CHECK(src.reconnects(0) == 0);
  CHECK(src.reconnects() == 1);
}

TEST_CASE("camera_v4l2 source: a device that stops is dark, retried, and back when it returns") {
  const std::filesystem::path dir = tmp_dir("stop");
  write_sequence(dir / "a", 60, 90);
  write_sequence(dir / "b", 60, 200);
  V4l2Source src(tiny_rig(), {(dir / "a" / "%06d.png").string(), (dir / "b" / "%06d.png").string()},
                 kFastRetry);
  CHECK(src.failed_devices().empty());
  Frame f;
  REQUIRE(src.grab(f));
  CHECK_FALSE(f.images[1].empty());
  CHECK(src.dark_mask() == 0u);
  std::filesystem::rename(dir / "b", dir / "b.unplugged");  // the device goes away
  REQUIRE(grab_until(src, f, 1, true));
  CHECK(src.dark_mask() == 0x2u);
  for (int i = 0; i < 5; ++i) {  // reopen attempts fail while it is away
    REQUIRE(src.grab(f));
    CHECK(f.images[1].empty());
    CHECK_FALSE(f.images[0].empty());
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  CHECK(src.reconnects(1) == 0);
  std::filesystem::rename(dir / "b.unplugged", dir / "b");  // plugged in again
  REQUIRE(grab_until(src, f, 1, false));
  CHECK(f.images[1].at<std::uint8_t>(10, 10) == 200);
  CHECK(src.dark_mask() == 0u);
  CHECK(src.reconnects(1) == 1);
  CHECK(src.reconnects(0) == 0);
}

TEST_CASE("camera_v4l2 source: bad reconnect times and device counts are refused") {
  const std::vector<std::string> two{"/dev/video97", "/dev/video98"};
  CHECK_THROWS_WITH_AS(V4l2Source(tiny_rig(), two, {.initial_s = 0.0, .max_s = 1.0}),
                       doctest::Contains("reconnect"), crease::ConfigError);
  CHECK_THROWS_WITH_AS(V4l2Source(tiny_rig(), two, {.initial_s = 2.0, .max_s = 1.0}),
                       doctest::Contains("reconnect"), crease::ConfigError);
  CHECK_THROWS_WITH_AS(V4l2Source(tiny_rig(), {"/dev/video97"}), doctest::Contains("1 devices for 2"),
                       crease::ConfigError);
  V4l2Source none(tiny_rig(), two, kFastRetry);  // nothing opens: dark, never ends
  Frame f;
  CHECK(none.grab(f));
  CHECK(none.dark_mask() == 0x3u);
  CHECK(f.images.size() == 2);
  CHECK(f.images[0].empty());
}
