// The camera source plugins (plugins/cameras: camera_replay, camera_sim on the sheet_truth
// plugin's sheet, camera_v4l2) feeding the `vision` plugin in a real loop: key-points on the
// `keypoints` port, frame sets through one frame channel (the host's port of kind frames that
// both dlopen'd plugins bound, listed with the other ports); degraded, never stopped, when a
// camera stops; a replay processed twice gives the same key-points; either end hot-swapped.
#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <thread>

#include "core/daemon/views.h"
#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "core/port_types/figure.h"
#include "core/port_types/keypoints.h"
#include "plugins/camera_rig/marker_sheet.h"
#include "plugins/cameras/camera_source.h"
#include "plugins/cameras/replay_source.h"
#include "plugins/sim_world/scene/sim_source.h"
#include "rt/alloc_guard.h"
#include "support/host_poll.h"
#include "support/instance_spec.h"

using namespace std::chrono_literals;
using namespace crease::vision;
namespace fs = std::filesystem;

namespace {
const std::string kSrc = CREASE_SOURCE_DIR;

fs::path tmp(const std::string& name) {
  const auto dir =
      fs::temp_directory_path() / ("crease_vision_plugin_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  return dir;
}

// Renders `frames` frames of the shipped rig (the sheet folding by 0.3 rad a frame) and
// records them in the replay layout.
std::string record_sequence(const std::string& name, int frames, double fold_per_frame = 0.0) {
  const auto dir = tmp(name);
  const MarkerLayout layout = load_layout(kSrc + "/config/markers/layout.yaml");
  const auto cams = load_camera_dir(kSrc + "/config/cameras");
  auto r = std::make_shared<const ViewRenderer>(face_texture(layout, Face::kFront, 8),
                                                face_texture(layout, Face::kBack, 8), 8, cams);
  const SheetMesh flat = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
  SimSource sim(
      r,
      [&](std::uint64_t i) {
        return fold_sheet(flat, layout.sheet_h_mm / 2, fold_per_frame * double(i));
      },
      RenderOptions{.seed = 3, .occluders = 1}, 33'000'000);
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
  explicit Fixture(double rate_hz = 30.0) { host.add_loop({"vision", rate_hz, 0, -1}); }
  // Relative paths resolve against config/ (the file named here).
  // `channel`: the global name of the plugin's `images` port (empty: the default, "images").
  void add(const std::string& name, const std::string& library, int order,
           const std::string& yaml, const std::string& channel = "") {
    crease::InstanceSpec s = crease::testing::instance_spec(name, library, "vision", order, yaml);
    if (!channel.empty()) s.ports["images"] = channel;
    host.add_instance(s);
  }
  // The sheet camera_sim renders: the sheet_truth plugin's, on the `sheet_truth` port.
  void add_truth(const std::string& more = "") {
    add("truth", "sheet_truth", 1, "{nodes_u: 15" + more + "}");
  }
  void add_vision(const std::string& cameras_dir, const std::string& channel,
                  const std::string& more = "") {
    add("vision", "vision", 10,
        "{cameras: '" + cameras_dir + "', layout: markers/layout.yaml" + more + "}", channel);
  }
  const crease::Keypoints& read() {
    const auto* ch = host.ports().find_latest("keypoints");
    REQUIRE(ch != nullptr);
    ch->read(kp.get(), 0);
    return *kp;
  }
  crease::CameraFrames frames() {
    crease::CameraFrames f{};
    const auto* ch = host.ports().find_latest("frames");
    REQUIRE(ch != nullptr);
    ch->read(&f, 0);
    return f;
  }
  std::uint64_t degraded(const std::string& name) {
    for (const auto& i : host.instances())
      if (i.name == name) return i.stats->degraded.load();
    return 0;
  }
  crease::RunState state(const std::string& name) {
    for (const auto& i : host.instances())
      if (i.name == name) return i.state;
    return crease::RunState::inactive;
  }
  template <class P>
  bool wait_for(P pred) {
    return crease::testing::poll_until(host, pred, std::chrono::seconds(30), std::chrono::milliseconds(5));
  }
};

// Plays `dir` through camera_replay -> vision; key-points by vision frame.
std::map<std::uint64_t, crease::Keypoints> replay_keypoints(const std::string& dir,
                                                            const std::string& channel) {
  Fixture fx(10.0);  // slow enough that the test sees every frame's key-points on the port
  fx.add("cameras", "camera_replay", 5, "{replay_dir: '" + dir + "'}", channel);
  fx.add_vision(dir, channel);
  fx.host.start();
  std::map<std::uint64_t, crease::Keypoints> out;
  const auto ch = fx.host.ports().find_frames(channel);
  REQUIRE(ch != nullptr);
  REQUIRE(fx.wait_for([&] {
    if (fx.read().count > 0) out.emplace(fx.kp->frame, *fx.kp);
    // Done when the replay ended and the last set's key-points are on the port.
    return fx.frames().ended != 0 && !out.empty() && out.rbegin()->first + 1 == ch->published();
  }));
  fx.host.stop();
  return out;
}
}  // namespace

TEST_CASE(
    "camera_replay -> vision: one channel for both plugins; a camera that stops makes both "
    "degraded") {
  const std::string dir = record_sequence("gap", 4);
  fs::remove(dir + "/cam2/000002.png");
  fs::remove(dir + "/cam2/000003.png");
  Fixture fx;
  fx.add("cameras", "camera_replay", 5, "{replay_dir: '" + dir + "'}", "gap");
  fx.add_vision(dir, "gap");
  // Both dlopen'd plugins bound the same channel, and the host lists it.
  const auto ch = fx.host.ports().find_frames("gap");
  REQUIRE(ch != nullptr);
  CHECK(ch->writer_claimed());
  CHECK(ch->reader_claimed());
  fx.host.start();
  REQUIRE(fx.wait_for([&] { return fx.read().frame >= 1 && fx.read().count > 0; }));
  // From here on the loop thread (marked RT) runs both plugins' updates: nothing allocates.
  REQUIRE(crease::rt::alloc_hooks_installed());  // the count below means something
  const auto allocations = crease::rt::rt_allocation_count();
  CHECK(fx.read().count == 35 * 5);
  CHECK(fx.read().cameras_ok == 0x1f);
  REQUIRE(fx.wait_for([&] { return fx.read().frame >= 3; }));
  CHECK(fx.read().cameras_ok == 0x1b);  // camera 2 gone, the others still triangulate
  CHECK(fx.read().count == 35 * 5);
  REQUIRE(fx.wait_for([&] { return fx.frames().ended != 0; }));
  CHECK(ch->published() == 4);
  CHECK(ch->consumed() == 4);  // lockstep: the vision worker took every set
  CHECK(std::string(fx.frames().channel) == "gap");
  CHECK(fx.frames().cameras == 5);
  CHECK(fx.degraded("cameras") > 0);
  CHECK(fx.degraded("vision") > 0);
  CHECK(fx.state("cameras") == crease::RunState::active);
  CHECK(fx.state("vision") == crease::RunState::active);
  CHECK(crease::rt::rt_allocation_count() == allocations);
  fx.host.stop();
}

TEST_CASE("camera_replay -> vision twice: identical key-points, frame by frame") {
  const std::string dir = record_sequence("twice", 3, 0.3);
  const auto a = replay_keypoints(dir, "twice.a");
  const auto b = replay_keypoints(dir, "twice.b");
  REQUIRE(a.size() >= 2);  // the poller saw most frames (every one at this rate)
  CHECK(a.rbegin()->first == 2);
  CHECK(b.rbegin()->first == 2);
  int compared = 0;
  for (const auto& entry : a) {
    const auto frame = entry.first;  // a plain variable: CAPTURE takes it into a lambda
    const auto& ka = entry.second;
    const auto it = b.find(frame);
    if (it == b.end()) continue;
    const crease::Keypoints& kb = it->second;
    CAPTURE(frame);
    // Stamped with each replay's own time, never closer than recorded (this 10 Hz loop makes
    // every frame of the 30 Hz recording late: each is stamped when it is handed out).
    const auto since_first = [&](const auto& run, const crease::Keypoints& k) {
      return k.timestamp_ns - run.begin()->second.timestamp_ns;
    };
    const auto recorded = static_cast<std::int64_t>(frame - a.begin()->first) * 33'000'000;
    CHECK(since_first(a, ka) >= recorded);
    if (b.begin()->first == a.begin()->first) CHECK(since_first(b, kb) >= recorded);
    REQUIRE(ka.count == kb.count);
    CHECK(ka.count > 100);
    CHECK(std::memcmp(ka.points, kb.points, sizeof(crease::Keypoint) * ka.count) == 0);
    ++compared;
  }
  CHECK(compared >= 2);
}

TEST_CASE("camera_sim -> vision with the shipped cameras and layout, recording what it renders") {
  const auto rec = tmp("simrec");
  Fixture fx;
  fx.add_truth(", start_s: 0");  // the half fold starts at once
  fx.add("cameras", "camera_sim", 5, "{occluders: 1, record: '" + rec.string() + "'}", "sim");
  fx.add_vision("cameras", "sim", ", camera_threads: 3");  // cameras on threads of ours
  fx.host.start();
  REQUIRE(fx.wait_for([&] { return fx.read().frame >= 2; }));
  CHECK(fx.read().count > 100);
  CHECK(fx.read().cameras_ok == 0x1f);
  CHECK(fx.read().timestamp_ns > 0);  // CLOCK_MONOTONIC capture time
  CHECK(fx.frames().sequence >= 3);
  CHECK(fx.frames().valid_mask == 0x1f);
  // Its figures: the worker's detection time per set and the key-points of the sets taken.
  crease::Figure detect{}, per_set{};
  fx.host.ports().find_latest("keypoints_per_set")->read(&per_set, 0);
  fx.host.ports().find_latest("detect_time")->read(&detect, 0);
  CHECK(detect.count >= per_set.count);  // every set taken was processed; some processed may not be taken yet
  CHECK(per_set.count >= 2);
  CHECK(detect.mean() > 0.0);
  CHECK(detect.max >= detect.last);
  CHECK(per_set.last > 100.0);
  CHECK(per_set.max >= per_set.last);
  CHECK(per_set.mean() > 100.0);
  fx.host.stop();
  CHECK(fs::exists(rec / "cam0.yaml"));
  CHECK(fs::exists(rec / "cam4" / "000001.png"));
  ReplaySource replay(rec.string());
  CHECK(replay.frames() >= 2);
}

TEST_CASE("camera_v4l2 on image sequences and a missing /dev/video: the others go on, degraded") {
  // Three of the shipped cameras; two "devices" are image sequences cv::VideoCapture opens, the
  // third a video device that does not exist here.
  const auto dir = tmp("v4l2");
  fs::create_directories(dir / "cams");
  for (int k = 0; k < 3; ++k)
    fs::copy_file(kSrc + "/config/cameras/cam" + std::to_string(k) + ".yaml",
                  dir / "cams" / ("cam" + std::to_string(k) + ".yaml"));
  {
    const MarkerLayout layout = load_layout(kSrc + "/config/markers/layout.yaml");
    const auto cams = load_camera_dir((dir / "cams").string());
    auto r = std::make_shared<const ViewRenderer>(face_texture(layout, Face::kFront, 8),
                                                  face_texture(layout, Face::kBack, 8), 8, cams);
    const SheetMesh flat = flat_sheet(22, 31, layout.sheet_w_mm, layout.sheet_h_mm, {0, 0, 0}, 0.1);
    SimSource sim(
        r, [&](std::uint64_t) { return flat; }, RenderOptions{}, 33'000'000);
    Recorder rec((dir / "rec").string(), cams);  // camK/NNNNNN.png: an image sequence per camera
    Frame f;
    for (int i = 0; i < 3; ++i) {
      REQUIRE(sim.grab(f));
      rec.write(f);
    }
  }
  const std::string devices = "['" + (dir / "rec" / "cam0" / "%06d.png").string() + "', '" +
                              (dir / "rec" / "cam1" / "%06d.png").string() + "', /dev/video97]";
  {
    Fixture fx;
    fx.add("cameras", "camera_v4l2", 5,
           "{cameras: '" + (dir / "cams").string() + "', devices: " + devices + "}", "v4l2");
    fx.add_vision((dir / "cams").string(), "v4l2");
    fx.host.start();
    REQUIRE(fx.wait_for([&] { return fx.read().count > 0; }));
    const auto allocations = crease::rt::rt_allocation_count();
    CHECK(fx.read().cameras_ok == 0x3u);
    CHECK(fx.read().count == 35 * 5);  // two views triangulate every key-point
    REQUIRE(fx.wait_for([&] { return fx.degraded("cameras") > 0 && fx.degraded("vision") > 0; }));
    CHECK(fx.state("cameras") == crease::RunState::active);
    CHECK(fx.state("vision") == crease::RunState::active);
    CHECK(crease::rt::rt_allocation_count() == allocations);  // updates allocate nothing
    fx.host.stop();
  }  // unloads both plugins: their workers release the channel's ends

  // No device at all: still configures and runs, degraded.
  Fixture none;
  none.add("cameras", "camera_v4l2", 5,
           "{cameras: '" + (dir / "cams").string() +
               "', devices: [/dev/video97, /dev/video98, /dev/video99]}",
           "v4l2");
  none.add_vision((dir / "cams").string(), "v4l2");
  none.host.start();
  REQUIRE(none.wait_for([&] {
    return none.frames().sequence > 0 && none.degraded("cameras") > 0 &&
           none.degraded("vision") > 0;
  }));
  CHECK(none.frames().valid_mask == 0u);
  CHECK(none.state("cameras") == crease::RunState::active);
  none.host.stop();
}

TEST_CASE("hot swaps of camera_sim and vision: the new instances take over the channel's ends") {
  Fixture fx;
  fx.add_truth();
  fx.add("cameras", "camera_sim", 5, "{}", "swap");
  fx.add_vision("cameras", "swap");
  fx.host.start();
  const auto ch = fx.host.ports().find_frames("swap");
  REQUIRE(ch != nullptr);
  const auto* kp_port = fx.host.ports().find_latest("keypoints");
  REQUIRE(kp_port != nullptr);
  // Key-points keep coming: the port's sequence grows by `n` with sets processed.
  auto keeps_going = [&](std::uint64_t n) {
    const std::uint64_t from = kp_port->sequence();
    return fx.wait_for([&] { return kp_port->sequence() >= from + n && fx.read().count > 100; });
  };
  REQUIRE(keeps_going(2));

  fx.host.swap("vision", "vision");  // the new worker waits for the old one's reader end
  REQUIRE(keeps_going(3));
  CHECK(ch->reader_claimed());
  fx.host.swap("cameras", "camera_sim");  // and the new camera worker for the writer end
  const std::uint64_t published = ch->published();
  REQUIRE(keeps_going(3));
  CHECK(ch->published() > published);
  CHECK(ch->writer_claimed());
  CHECK(fx.state("cameras") == crease::RunState::active);
  CHECK(fx.state("vision") == crease::RunState::active);
  CHECK(fx.host.fault_count() == 0);
  fx.host.stop();
}

TEST_CASE("the frame channel between camera_sim and vision is listed with the ports") {
  Fixture fx;
  fx.add_truth();
  fx.add("cameras", "camera_sim", 5, "{}");  // default names: images (frames), frames (latest)
  fx.add_vision("cameras", "");
  fx.host.start();
  REQUIRE(fx.wait_for([&] { return fx.read().frame >= 2; }));
  // What `creasectl ports` shows (the daemon's `ports` command answers with this view).
  const nlohmann::json ports = crease::daemon::ports_view(fx.host.ports());
  const nlohmann::json* images = nullptr;
  for (const auto& p : ports)
    if (p["name"] == "images") images = &p;
  REQUIRE(images != nullptr);
  CHECK((*images)["kind"] == "frames");
  CHECK((*images)["type"] == "crease.FrameSet");
  CHECK((*images)["writer"] == "cameras");
  CHECK((*images)["readers"] == nlohmann::json::array({"vision"}));
  CHECK((*images)["cameras"].size() == 5);
  CHECK((*images)["cameras"][0] == "cam0 1280x960");
  CHECK((*images)["size"] == 5 * 1280 * 960);
  CHECK((*images)["published"].get<std::uint64_t>() >= 3);
  CHECK((*images)["consumed"].get<std::uint64_t>() >= 3);
  CHECK(std::string(fx.frames().channel) == "images");
  fx.host.stop();
}
