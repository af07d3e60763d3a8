// The camera_depth_v4l2 plugin in a loop on this machine, which has no depth camera: its camera
// is dark (status degraded), the loop runs on and the depth_frames port is there for
// depth_tracking; and its configure errors, each naming the key. (The streaming itself:
// v4l2_depth_source_test.cpp and v4l2_z16_device_test.cpp, against an emulated node.)
#include <doctest/doctest.h>

#include <filesystem>

#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "plugins/camera_rig/depth_camera.h"
#include "support/host_poll.h"
#include "support/opencv_threads.h"

namespace fs = std::filesystem;

namespace {

fs::path calibrations(const std::string& name, bool carried) {
  const fs::path dir =
      fs::temp_directory_path() / ("crease_depth_v4l2_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  crease::vision::DepthCamera c;
  c.camera = crease::vision::look_at_camera("d405", 64, 48, 60, {0, 0, 300}, {0, 0, 0});
  c.depth_unit_mm = 0.1;
  if (carried) c.mount = crease::vision::CameraMount{};
  crease::vision::save_depth_camera(c, (dir / "cam0.yaml").string());
  return dir;
}

crease::InstanceSpec spec(const std::string& yaml) {
  crease::InstanceSpec s;
  s.name = "depth_cams";
  s.library = "camera_depth_v4l2";
  s.loop = "cams";
  s.params = crease::Params(YAML::Load(yaml), std::string(CREASE_SOURCE_DIR) + "/config/test.yaml",
                            "depth_cams.params");
  return s;
}

}  // namespace

TEST_CASE("camera_depth_v4l2 without its camera: dark and degraded, the loop runs on") {
  crease::testing::own_threads_only();
  const fs::path cams = calibrations("fixed", false);
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  host.add_loop({"cams", 50.0, 0, -1});
  host.add_instance(
      spec("{cameras: '" + cams.string() +
           "', depth_devices: [/dev/crease-no-depth], colour_devices: [/dev/crease-no-colour], "
           "wait_ms: 5, reconnect_initial_s: 0.02, reconnect_max_s: 0.05}"));
  host.start();
  const crease::PluginStats* stats = nullptr;
  for (const auto& i : host.instances())
    if (i.name == "depth_cams") stats = i.stats.get();
  REQUIRE(stats != nullptr);
  REQUIRE(crease::testing::poll_until(
      host, [&] { return stats->degraded.load() > 10; }, std::chrono::seconds(30),
      std::chrono::milliseconds(5)));
  crease::CameraFrames f{};
  const auto* ch = host.ports().find_latest("depth_frames");
  REQUIRE(ch != nullptr);
  ch->read(&f, 0);
  CHECK(f.valid_mask == 0u);  // nothing delivered
  for (const auto& i : host.instances()) CHECK(i.state == crease::RunState::active);
  CHECK(host.fault_count() == 0);
  host.stop();
}

TEST_CASE("camera_depth_v4l2's configure errors name the key") {
  const fs::path fixed = calibrations("fixed2", false), carried = calibrations("carried", true);
  struct Case {
    std::string yaml, key;
  };
  const Case cases[] = {
      {"{cameras: '" + fixed.string() + "', depth_devices: [], colour_devices: [/dev/video1]}",
       "depth_devices"},
      {"{cameras: '" + fixed.string() +
           "', depth_devices: [/dev/video0], colour_devices: /dev/video1}",
       "colour_devices"},
      {"{cameras: '" + fixed.string() +
           "', depth_devices: [/dev/video0], colour_devices: [/dev/video1], wait_ms: 0}",
       "wait_ms"},
      {"{cameras: '" + carried.string() +
           "', depth_devices: [/dev/video0], colour_devices: [/dev/video1]}",
       "carries"},
  };
  for (const Case& k : cases) {
    CAPTURE(k.yaml);
    crease::PluginHost host{{CREASE_PLUGIN_DIR}};
    host.add_loop({"cams", 50.0, 0, -1});
    CHECK_THROWS_WITH(host.add_instance(spec(k.yaml)), doctest::Contains(k.key.c_str()));
  }
}
