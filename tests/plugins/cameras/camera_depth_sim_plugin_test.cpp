// camera_depth_sim in a loop with `world_shapes: true`: the world's shapes of that port are taken
// every cycle and rendered by the worker (their depth: tests/plugins/sim_world/scene/
// depth_view_test.cpp); frame sets keep coming from both cameras and the update allocates nothing.
// The D405-like wrist cameras (config/wrist_cameras, carried on the forearms): no set holds them
// until the world's shapes come (each camera frame counted on `carried_unposed`), then both
// deliver; the configuration errors of a carried camera (tests/plugins/sim_world/scene/
// carried_camera_test.cpp: the images from the moved pose; `record` with them:
// camera_depth_replay_plugin_test.cpp).
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "core/errors.h"
#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "core/port_types/figure.h"
#include "core/port_types/world_shapes.h"
#include "plugins/camera_rig/depth_camera.h"
#include "support/host_poll.h"
#include "support/instance_spec.h"
#include "tests/plugins/cameras/wrist_shapes.h"

namespace {

// Every instance of HOST active, updated, and never allocating in its update.
void check_running_without_allocation(const crease::PluginHost& host) {
  for (const auto& i : host.instances()) {
    CAPTURE(i.name);
    CHECK(i.state == crease::RunState::active);
    CHECK(i.stats->updates.load() > 0);
    CHECK(i.stats->rt_allocations.load() == 0);
  }
}

}  // namespace

TEST_CASE(
    "camera_depth_sim with world_shapes: frame sets from both cameras, no allocation in its "
    "update") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"vision", 30.0, 0, -1});
  const auto add = [&](const std::string& name, const std::string& library, int order,
                       const std::string& yaml) {
    host.add_instance(crease::testing::instance_spec(name, library, "vision", order, yaml));
  };
  add("truth", "sheet_truth", 1, "{start_s: 1000}");
  add("depth_cams", "camera_depth_sim", 5,
      "{cameras: depth_cameras, sheet: plain, world_shapes: true}");
  crease::rt::LatestChannel* shapes_w = host.ports().bind_latest_writer(
      "world_shapes", crease::port_type_of<crease::WorldShapes>(), "test");
  REQUIRE(shapes_w != nullptr);
  auto shapes = std::make_unique<crease::WorldShapes>();
  shapes->count = 1;  // a fingertip 40 mm over the sheet's centre
  shapes->shapes[0].kind = crease::WorldShapes::Kind::sphere;
  shapes->shapes[0].radius_mm = 8;
  shapes->shapes[0].position_mm[2] = 40;
  host.start();
  crease::CameraFrames f{};
  const auto frames = [&] {
    host.ports().find_latest("depth_frames")->read(&f, 0);
    return f;
  };
  std::int64_t stamp = 1;
  const auto moved = [&] {  // the fingertip moves every poll: a new value every cycle or so
    shapes->shapes[0].position_mm[0] = static_cast<float>(stamp % 50);
    shapes_w->write(shapes.get(), stamp++);
    return frames().sequence >= 6;
  };
  REQUIRE(crease::testing::poll_until(host, moved, std::chrono::seconds(60),
                                      std::chrono::milliseconds(20)));
  CHECK(f.valid_mask == 0xf);  // each camera's depth and colour images
  check_running_without_allocation(host);
  host.stop();
}

namespace {

std::string configure_error(const std::string& yaml) {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"vision", 30.0, 0, -1});
  try {
    host.add_instance(
        crease::testing::instance_spec("wrist", "camera_depth_sim", "vision", 5, yaml));
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  return "configured";
}

}  // namespace

TEST_CASE(
    "camera_depth_sim wrist cameras: invalid and counted until the world's shapes come, then from "
    "the hands; no allocation in its update") {
  crease::PluginHost host({CREASE_PLUGIN_DIR});
  host.add_loop({"vision", 30.0, 0, -1});
  host.add_instance(
      crease::testing::instance_spec("truth", "sheet_truth", "vision", 1, "{start_s: 1000}"));
  host.add_instance(crease::testing::instance_spec(
      "wrist", "camera_depth_sim", "vision", 5,
      "{cameras: wrist_cameras, sheet: plain, world_shapes: true, sensor: d405}"));
  crease::rt::LatestChannel* shapes_w = host.ports().bind_latest_writer(
      "world_shapes", crease::port_type_of<crease::WorldShapes>(), "test");
  REQUIRE(shapes_w != nullptr);
  host.start();
  crease::CameraFrames f{};
  crease::Figure unposed{};
  const auto read = [&] {
    host.ports().find_latest("depth_frames")->read(&f, 0);
    host.ports().find_latest("carried_unposed")->read(&unposed, 0);
  };
  // No world_shapes yet: the sets come, neither camera in them, every camera frame counted.
  REQUIRE(crease::testing::poll_until(
      host,
      [&] {
        read();
        return f.sequence >= 3 && unposed.count >= 6;
      },
      std::chrono::seconds(60), std::chrono::milliseconds(20)));
  CHECK(f.valid_mask == 0);
  CHECK(unposed.mean() == doctest::Approx(100.0));
  CHECK(unposed.last == 100.0);
  for (const auto& i : host.instances()) CHECK(i.state == crease::RunState::active);
  // The forearms come: both wrist cameras look down at the sheet from 300 mm.
  const auto cams = crease::vision::load_depth_camera_dir(std::string(CREASE_SOURCE_DIR) +
                                                          "/config/wrist_cameras");
  auto shapes = std::make_unique<crease::WorldShapes>();
  wrist_shapes::forearm_carrying(cams[0].camera, 0, {60, 0, 300}, *shapes, 0);
  wrist_shapes::forearm_carrying(cams[1].camera, 1, {-60, 0, 300}, *shapes, 2);
  std::int64_t stamp = 1;
  REQUIRE(crease::testing::poll_until(
      host,
      [&] {
        shapes_w->write(shapes.get(), stamp++);
        read();
        return f.valid_mask == 0xf;
      },
      std::chrono::seconds(60), std::chrono::milliseconds(20)));
  CHECK(unposed.last == 0.0);
  CHECK(unposed.mean() < 100.0);
  check_running_without_allocation(host);
  host.stop();
}

TEST_CASE("camera_depth_sim wrist cameras: configuration errors name the file and the key") {
  const std::string file = "config/test.yaml:1:";
  std::string what = configure_error("{cameras: wrist_cameras}");
  CAPTURE(what);
  CHECK(what.find(file) != std::string::npos);
  CHECK(what.find("wrist.params.world_shapes: must be true: cam0 is carried (right hand #1)") !=
        std::string::npos);
  what = configure_error("{cameras: wrist_cameras, world_shapes: true, sensor: d415}");
  CHECK(what.find("wrist.params.sensor: must be d435 or d405, not 'd415'") != std::string::npos);
  // A wrist camera naming a side that does not exist: its file and key.
  const auto dir = std::filesystem::temp_directory_path() / "crease_wrist_bad_side";
  std::filesystem::create_directories(dir);
  {
    std::ifstream in(std::string(CREASE_SOURCE_DIR) + "/config/wrist_cameras/cam0.yaml");
    std::ofstream out(dir / "cam0.yaml");
    std::string line;
    while (std::getline(in, line))
      out << (line == "mount_side: right" ? "mount_side: middle" : line) << "\n";
  }
  what = configure_error("{cameras: " + dir.string() + ", world_shapes: true}");
  CHECK(what.find((dir / "cam0.yaml").string() +
                  ": key 'mount_side': 'middle' is no side: right | left") != std::string::npos);
  std::filesystem::remove_all(dir);
}
