// The `vision` plugin in a real loop: replaying a recording to the `keypoints` port, going
// degraded when a camera stops delivering and when the recording ends.
#include <chrono>
#include <filesystem>
#include <thread>

#include <doctest/doctest.h>

#include "camera_source.h"
#include "core/plugin_host.h"
#include "core/port_types/keypoints.h"
#include "marker_sheet.h"

using namespace std::chrono_literals;
using namespace crease::vision;

namespace {
std::string record_sequence(const std::string& name, int frames) {
  const auto dir = std::filesystem::temp_directory_path() / ("crease_vision_plugin_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  const MarkerLayout layout = load_layout(std::string(CREASE_SOURCE_DIR) + "/config/markers/layout.yaml");
  const auto cams = load_camera_dir(std::string(CREASE_SOURCE_DIR) + "/config/cameras");
  auto r = std::make_shared<const ViewRenderer>(face_texture(layout, Face::kFront, 8), face_texture(layout, Face::kBack, 8), 8, cams);
  const SheetMesh flat = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
  SimSource sim(r, [&](std::uint64_t) { return flat; }, RenderOptions{}, 33'000'000);
  Recorder rec(dir.string(), cams);
  Frame f;
  for (int i = 0; i < frames; ++i) {
    REQUIRE(sim.grab(f));
    rec.write(f);
  }
  return dir.string();
}

struct Fixture {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  std::unique_ptr<crease::Keypoints> kp = std::make_unique<crease::Keypoints>();
  Fixture() { host.add_loop({"vision", 30.0, 0, -1}); }
  void add(const std::string& replay_dir) {
    add_yaml("{source: replay, replay_dir: '" + replay_dir + "', layout: '" + std::string(CREASE_SOURCE_DIR) +
             "/config/markers/layout.yaml'}");
  }
  // Relative paths resolve against config/ (the file named here).
  void add_yaml(const std::string& yaml) {
    crease::InstanceSpec s;
    s.name = "vision";
    s.library = "vision";
    s.loop = "vision";
    s.params = crease::Params(YAML::Load(yaml), std::string(CREASE_SOURCE_DIR) + "/config/test.yaml", "vision.params");
    host.add_instance(s);
  }
  const crease::Keypoints& read() {
    const auto* ch = host.ports().find_latest("keypoints");
    REQUIRE(ch != nullptr);
    ch->read(kp.get(), 0);
    return *kp;
  }
  std::uint64_t degraded() {
    for (const auto& i : host.instances())
      if (i.name == "vision") return i.stats->degraded.load();
    return 0;
  }
  template <class P>
  bool wait_for(P pred) {
    for (int i = 0; i < 1000; ++i) {
      host.poll();
      if (pred()) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }
};
}  // namespace

TEST_CASE_FIXTURE(Fixture, "replay -> keypoints; a camera that stops makes it degraded, not stopped") {
  const std::string dir = record_sequence("gap", 4);
  std::filesystem::remove(dir + "/cam2/000002.png");
  std::filesystem::remove(dir + "/cam2/000003.png");
  add(dir);
  host.start();
  REQUIRE(wait_for([&] { return read().frame >= 1 && read().count > 0; }));
  CHECK(read().count == 35 * 5);
  CHECK(read().cameras_ok == 0x1f);
  REQUIRE(wait_for([&] { return read().frame >= 3; }));
  CHECK(read().cameras_ok == 0x1b);  // camera 2 gone, the others still triangulate
  CHECK(read().count == 35 * 5);
  CHECK(degraded() > 0);
  host.stop();
}

TEST_CASE_FIXTURE(Fixture, "sim source with the shipped cameras and layout, recording what it renders") {
  const auto rec = std::filesystem::temp_directory_path() / ("crease_vision_plugin_" + std::to_string(::getpid())) / "simrec";
  std::filesystem::remove_all(rec);
  add_yaml("{source: sim, occluders: 1, fold_start_s: 0, fold_duration_s: 1, record: '" + rec.string() + "'}");
  host.start();
  REQUIRE(wait_for([&] { return read().frame >= 2; }));
  CHECK(read().count > 100);
  CHECK(read().timestamp_ns > 0);  // CLOCK_MONOTONIC capture time
  host.stop();
  CHECK(std::filesystem::exists(rec / "cam0.yaml"));
  CHECK(std::filesystem::exists(rec / "cam4" / "000001.png"));
  ReplaySource replay(rec.string());
  CHECK(replay.frames() >= 2);
}
