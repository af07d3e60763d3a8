// camera_depth_sim's `record: DIR` writes the depth layout (camera_source.h), and
// camera_depth_replay plays it back into `depth_images` / `depth_frames` as camera_depth_sim
// published it: every recorded frame set, both cameras' depth and colour, in order, then the
// end; its update allocates nothing. camera_replay refuses a depth recording and
// camera_depth_replay a grey one, each naming the key.
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "plugins/camera_rig/camera_model.h"
#include "plugins/cameras/replay_reader.h"
#include "support/host_poll.h"
#include "support/instance_spec.h"

namespace {

crease::CameraFrames frames_of(crease::PluginHost& host) {
  crease::CameraFrames f{};
  host.ports().find_latest("depth_frames")->read(&f, 0);
  return f;
}

}  // namespace

TEST_CASE(
    "a depth run recorded with record: plays back through camera_depth_replay, every frame set") {
  const auto dir =
      std::filesystem::temp_directory_path() / ("crease_depth_rec_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  {
    crease::PluginHost host({CREASE_PLUGIN_DIR});
    host.add_loop({"vision", 30.0, 0, -1});
    host.add_instance(
        crease::testing::instance_spec("truth", "sheet_truth", "vision", 1, "{start_s: 0}"));
    host.add_instance(crease::testing::instance_spec(
        "depth_cams", "camera_depth_sim", "vision", 5,
        "{cameras: depth_cameras, sheet: plain, record: " + dir.string() + "}"));
    host.start();
    REQUIRE(crease::testing::poll_until(
        host, [&] { return frames_of(host).sequence >= 6; }, std::chrono::seconds(60),
        std::chrono::milliseconds(20)));
    host.stop();
  }
  const crease::vision::ReplayReader rec(dir.string());
  REQUIRE(rec.frames() >= 6);
  CHECK(rec.depth_units_mm() ==
        std::vector<double>{1.0, 1.0});  // config/depth_cameras: D435s, 1 mm

  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"vision", 30.0, 0, -1});
  host.add_instance(crease::testing::instance_spec("replay", "camera_depth_replay", "vision", 5,
                                                   "{replay_dir: " + dir.string() + "}"));
  host.start();
  std::uint64_t seen = 0, all_valid = 0;
  const auto ended = [&] {
    const crease::CameraFrames f = frames_of(host);
    if (f.sequence != seen) {
      seen = f.sequence;
      all_valid += f.valid_mask == 0xf;  // each camera's depth and colour
    }
    return f.ended != 0;
  };
  REQUIRE(crease::testing::poll_until(host, ended, std::chrono::seconds(60),
                                      std::chrono::milliseconds(5)));
  CHECK(frames_of(host).sequence == rec.frames());
  CHECK(all_valid >= 1);
  for (const auto& i : host.instances()) {
    CAPTURE(i.name);
    CHECK(i.stats->rt_allocations.load() == 0);
  }
  host.stop();

  // Each replay plugin refuses the other's recording.
  const auto error_of = [&](const std::string& library, const std::string& replay_dir) {
    crease::PluginHost h({CREASE_PLUGIN_DIR});
    h.add_loop({"vision", 30.0, 0, -1});
    try {
      h.add_instance(crease::testing::instance_spec("r", library, "vision", 5,
                                                    "{replay_dir: " + replay_dir + "}"));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(error_of("camera_replay", dir.string()).find("use camera_depth_replay") !=
        std::string::npos);
  const auto grey = dir.string() + "_grey";  // a grey camera's recording of one frame
  std::filesystem::create_directories(grey + "/cam0");
  crease::vision::save_camera(
      crease::vision::look_at_camera("a", 64, 48, 60, {0, -60, 450}, {0, 0, 0}),
      grey + "/cam0.yaml");
  std::ofstream(grey + "/timestamps.csv") << "frame,timestamp_ns\n0,0\n";
  CHECK(error_of("camera_depth_replay", grey).find("use camera_replay") != std::string::npos);
  CHECK(error_of("camera_replay", grey).empty());
  std::filesystem::remove_all(dir);
  std::filesystem::remove_all(grey);
}
