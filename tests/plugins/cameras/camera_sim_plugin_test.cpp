// camera_sim renders the sheet of its `sheet_truth` port and nothing of its own: with no
// writer on the port its cameras see the empty table (vision finds no key-point), and the
// key-points follow the truth wherever the sheet_truth plugin puts the sheet. With
// `world_shapes: true` it draws the world's shapes of that port: a fingertip laid over a marker
// takes the marker from vision, and it is back once the fingertip is gone; its update allocates
// nothing. The analytic fold
// it once kept (fold_start_s, fold_duration_s, fold_angle_deg, truth) is gone: a configuration
// that still names it is refused with the file, line and key.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>

#include "core/errors.h"
#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "core/port_types/keypoints.h"
#include "core/port_types/world_shapes.h"
#include "support/host_poll.h"
#include "support/instance_spec.h"

using namespace std::chrono_literals;

namespace {

struct Fixture {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  std::unique_ptr<crease::Keypoints> kp = std::make_unique<crease::Keypoints>();
  Fixture() { host.add_loop({"vision", 30.0, 0, -1}); }
  // Relative paths resolve against config/ (the file named here).
  void add(const std::string& name, const std::string& library, int order,
           const std::string& yaml) {
    host.add_instance(crease::testing::instance_spec(name, library, "vision", order, yaml));
  }
  // The shipped rig and layout: camera_sim, then vision on its frame sets.
  void add_cameras_and_vision() {
    add("cameras", "camera_sim", 5, "{cameras: cameras, layout: markers/layout.yaml}");
    add("vision", "vision", 10, "{cameras: cameras, layout: markers/layout.yaml}");
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
  template <class P>
  bool wait_for(P pred) {
    return crease::testing::poll_until(host, pred, std::chrono::seconds(30), std::chrono::milliseconds(5));
  }
  // Mean world x of the key-points of one vision frame with some, mm.
  double mean_x() {
    REQUIRE(wait_for([&] { return read().frame >= 2 && read().count > 100; }));
    double sum = 0;
    for (std::uint32_t i = 0; i < kp->count; ++i) sum += kp->points[i].world_mm[0];
    return sum / kp->count;
  }
};
}  // namespace

TEST_CASE("camera_sim without a sheet on its port: the cameras see the empty table") {
  Fixture fx;
  fx.add_cameras_and_vision();  // nothing writes `sheet_truth`
  fx.host.start();
  // Frame sets keep coming from every camera, and vision has processed several of them...
  REQUIRE(fx.wait_for([&] { return fx.frames().sequence >= 4 && fx.read().frame >= 3; }));
  CHECK(fx.frames().valid_mask == 0x1f);
  CHECK(fx.read().cameras_ok == 0x1f);
  // ...with no marker in them: camera_sim draws no sheet of its own.
  CHECK(fx.read().count == 0);
  fx.host.stop();
}

TEST_CASE("camera_sim renders the sheet_truth plugin's sheet where that plugin puts it") {
  // The flat sheet (the fold starts after 1000 s) centred on the table, then 20 mm further
  // along x: the key-points move with it.
  double x[2] = {};
  const double origin_x[2] = {-105.0, -85.0};
  for (int k = 0; k < 2; ++k) {
    Fixture fx;
    fx.add("truth", "sheet_truth", 1,
           "{start_s: 1000, origin_x_mm: " + std::to_string(origin_x[k]) + "}");
    fx.add_cameras_and_vision();
    fx.host.start();
    x[k] = fx.mean_x();
    CHECK(fx.read().cameras_ok == 0x1f);
    fx.host.stop();
  }
  CAPTURE(x[0]);
  CAPTURE(x[1]);
  CHECK(std::abs(x[0]) < 10.0);  // the layout's markers are about centred on the sheet
  CHECK(x[1] - x[0] == doctest::Approx(20.0).epsilon(0.05));
}

TEST_CASE(
    "camera_sim with world_shapes: a fingertip over a marker hides it from vision; gone, the "
    "marker is back") {
  Fixture fx;
  fx.add("truth", "sheet_truth", 1, "{start_s: 1000}");  // flat, centred on the table
  fx.add("cameras", "camera_sim", 5,
         "{cameras: cameras, layout: markers/layout.yaml, world_shapes: true}");
  fx.add("vision", "vision", 10, "{cameras: cameras, layout: markers/layout.yaml}");
  crease::rt::LatestChannel* shapes_w = fx.host.ports().bind_latest_writer(
      "world_shapes", crease::port_type_of<crease::WorldShapes>(), "test");
  REQUIRE(shapes_w != nullptr);
  fx.host.start();
  REQUIRE(fx.wait_for([&] { return fx.read().frame >= 2 && fx.read().count > 100; }));
  // The marker whose centre is nearest the table's origin.
  int id = -1;
  float at[3] = {};
  double best = 1e9;
  for (std::uint32_t i = 0; i < fx.kp->count; ++i) {
    const crease::Keypoint& k = fx.kp->points[i];
    const double d = std::hypot(k.world_mm[0], k.world_mm[1]);
    if (k.corner == 0 && d < best) {
      best = d;
      id = k.marker_id;
      std::copy(k.world_mm, k.world_mm + 3, at);
    }
  }
  REQUIRE(id >= 0);
  CAPTURE(id);
  const auto seen = [&](int marker) {
    for (std::uint32_t i = 0; i < fx.kp->count; ++i)
      if (fx.kp->points[i].marker_id == marker) return true;
    return false;
  };
  // A distal phalanx (capsule r 9 mm, 38 mm long, along x) 3 mm over that marker.
  auto shapes = std::make_unique<crease::WorldShapes>();
  shapes->count = 1;
  crease::WorldShapes::Shape& tip = shapes->shapes[0];
  tip.kind = crease::WorldShapes::Kind::capsule;
  tip.role = crease::WorldShapes::Role::fingertip;
  tip.radius_mm = 9;
  tip.half_length_mm = 10;
  const float along_x[9] = {0, 0, 1, 0, 1, 0, -1, 0, 0};
  std::copy(along_x, along_x + 9, tip.rotation);
  tip.position_mm[0] = at[0];
  tip.position_mm[1] = at[1];
  tip.position_mm[2] = at[2] + 12;
  shapes_w->write(shapes.get(), 1);
  std::uint64_t from = fx.read().frame;
  CHECK(fx.wait_for([&] { return fx.read().frame > from + 1 && !seen(id) && fx.kp->count > 100; }));
  // The fingertip gone (no shape): the marker is seen again.
  shapes->count = 0;
  shapes_w->write(shapes.get(), 2);
  from = fx.read().frame;
  CHECK(fx.wait_for([&] { return fx.read().frame > from + 1 && seen(id); }));
  for (const auto& i : fx.host.instances()) {  // none faulted; none allocated in a cycle
    CAPTURE(i.name);
    CHECK(i.state == crease::RunState::active);
    CHECK(i.stats->updates.load() > 0);
    CHECK(i.stats->rt_allocations.load() == 0);
  }
  fx.host.stop();
}

TEST_CASE("camera_sim refuses its removed fold parameters with the file, line and key") {
  for (const std::string key : {"fold_start_s", "fold_duration_s", "fold_angle_deg", "truth"}) {
    CAPTURE(key);
    Fixture fx;
    try {
      fx.add("cameras", "camera_sim", 5,
             "cameras: cameras\nlayout: markers/layout.yaml\n" + key + ": 1\n");
      FAIL("configured");
    } catch (const crease::ConfigError& e) {
      const std::string what = e.what();
      CAPTURE(what);
      // Line 3, at the key's value (column after "KEY: ").
      const std::string where = "config/test.yaml:3:" + std::to_string(key.size() + 3) + ": ";
      CHECK(what.find(where + "cameras.params." + key + ": unknown parameter") !=
            std::string::npos);
    }
  }
}
