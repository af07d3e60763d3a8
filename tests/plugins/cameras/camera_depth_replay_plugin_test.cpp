// camera_depth_sim's `record: DIR` writes the depth layout (camera_source.h), and
// camera_depth_replay plays it back into `depth_images` / `depth_frames` as camera_depth_sim
// published it: every recorded frame set, both cameras' depth and colour, in order, then the
// end; its update allocates nothing. camera_replay refuses a depth recording and
// camera_depth_replay a grey one, each naming the key. The wrist cameras (carried on the forearms)
// record their pose per frame, and the replay hands each set out with the recorded poses, bit for
// bit.
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "core/port_types/world_shapes.h"
#include "plugins/camera_rig/camera_model.h"
#include "plugins/camera_rig/depth_camera.h"
#include "plugins/cameras/replay_reader.h"
#include "support/host_poll.h"
#include "support/instance_spec.h"
#include "tests/plugins/cameras/wrist_shapes.h"

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

TEST_CASE(
    "wrist cameras recorded with record: their pose per frame, played back bit for bit with their "
    "images") {
  const auto dir =
      std::filesystem::temp_directory_path() / ("crease_wrist_rec_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const auto cams = crease::vision::load_depth_camera_dir(std::string(CREASE_SOURCE_DIR) +
                                                          "/config/wrist_cameras");
  {
    crease::PluginHost host({CREASE_PLUGIN_DIR});
    host.add_loop({"vision", 30.0, 0, -1});
    host.add_instance(
        crease::testing::instance_spec("truth", "sheet_truth", "vision", 1, "{start_s: 1000}"));
    host.add_instance(crease::testing::instance_spec(
        "wrist", "camera_depth_sim", "vision", 5,
        "{cameras: wrist_cameras, sheet: plain, world_shapes: true, sensor: d405, record: " +
            dir.string() + "}"));
    crease::rt::LatestChannel* shapes_w = host.ports().bind_latest_writer(
        "world_shapes", crease::port_type_of<crease::WorldShapes>(), "test");
    REQUIRE(shapes_w != nullptr);
    auto shapes = std::make_unique<crease::WorldShapes>();
    host.start();
    std::int64_t stamp = 1;
    // The right arm sweeps 0..39 mm along x (a new pose nearly every frame), the left one holds.
    REQUIRE(crease::testing::poll_until(
        host,
        [&] {
          wrist_shapes::forearm_carrying(
              cams[0].camera, 0, {60.0 + static_cast<double>(stamp % 40), 0, 300}, *shapes, 0);
          wrist_shapes::forearm_carrying(cams[1].camera, 1, {-60, 0, 300}, *shapes, 2);
          shapes_w->write(shapes.get(), stamp++);
          return frames_of(host).sequence >= 8;
        },
        std::chrono::seconds(60), std::chrono::milliseconds(20)));
    host.stop();
  }
  // The recording: each camera's pose where the forearm put it (the port's shapes are floats:
  // within their precision), the right one's moving.
  const crease::vision::ReplayReader rec(dir.string());
  REQUIRE(rec.frames() >= 8);
  REQUIRE(rec.any_carried());
  std::vector<crease::vision::Frame> recorded(rec.frames());
  std::set<double> right_x;
  int posed = 0;
  for (std::size_t i = 0; i < rec.frames(); ++i) {
    rec.read(i, recorded[i]);
    REQUIRE(recorded[i].poses.size() == 4);
    for (std::size_t k = 0; k < 2; ++k) {
      const crease::frames::CameraPose& p = recorded[i].poses[2 * k];
      CHECK(p.carried == !recorded[i].images[2 * k].empty());
      if (!p.carried) continue;
      ++posed;
      CHECK(std::abs(p.translation_mm[2] - 300) < 1e-3);
      CHECK(std::abs(p.rotation[4] + 1) < 1e-5);  // looking down: the camera's y along -y
      CHECK(std::abs(p.rotation[8] + 1) < 1e-5);
      if (k == 0) right_x.insert(std::round(p.translation_mm[0] * 1e3) / 1e3);
      if (k == 1) CHECK(std::abs(p.translation_mm[0] + 60) < 1e-3);
    }
  }
  MESSAGE(rec.frames() << " frames recorded, " << posed
                       << " camera frames posed, the right camera at " << right_x.size()
                       << " places");
  CHECK(posed >= 8);
  CHECK(right_x.size() >= 3);

  // The replay, read as depth_tracking would: each set's poses are the recorded ones, bit for bit.
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"vision", 30.0, 0, -1});
  host.add_instance(crease::testing::instance_spec("replay", "camera_depth_replay", "vision", 5,
                                                   "{replay_dir: " + dir.string() + "}"));
  const auto channel = host.ports().bind_frames_reader(
      "depth_images", crease::vision::depth_channel_specs(rec.cameras()), "test");
  REQUIRE(channel->try_claim_reader());
  host.start();
  std::size_t sets = 0, same = 0, posed_sets = 0;
  const auto take = [&] {
    const crease::frames::FrameSet* set = channel->acquire_newest();
    if (set == nullptr) return;
    ++sets;
    for (std::size_t i = 0; i < recorded.size(); ++i) {
      if (recorded[i].index != set->frame) continue;
      bool all = true;
      for (std::size_t m = 0; m < 4; ++m) {
        const crease::frames::CameraPose& a = set->pose(m);
        const crease::frames::CameraPose& b = recorded[i].poses[m];
        all = all && a.carried == b.carried &&
              std::memcmp(a.rotation, b.rotation, sizeof a.rotation) == 0 &&
              std::memcmp(a.translation_mm, b.translation_mm, sizeof a.translation_mm) == 0;
        all = all && set->valid(m) == !recorded[i].images[m].empty();
      }
      same += all;
      posed_sets += set->pose(0).carried;
    }
    channel->finish(set->sequence);  // lockstep: the replay hands out the next one
  };
  REQUIRE(crease::testing::poll_until(
      host,
      [&] {
        take();
        return frames_of(host).ended != 0;
      },
      std::chrono::seconds(60), std::chrono::milliseconds(5)));
  take();
  channel->release_reader();
  host.stop();
  CHECK(sets == rec.frames());
  CHECK(same == sets);
  CHECK(posed_sets >= 4);
  std::filesystem::remove_all(dir);
}
