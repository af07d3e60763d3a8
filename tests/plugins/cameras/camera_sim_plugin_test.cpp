// camera_sim renders the sheet of its `sheet_truth` port and nothing of its own: with no
// writer on the port its cameras see the empty table (vision finds no key-point), and the
// key-points follow the truth wherever the sheet_truth plugin puts the sheet. The analytic fold
// it once kept (fold_start_s, fold_duration_s, fold_angle_deg, truth) is gone: a configuration
// that still names it is refused with the file, line and key.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>

#include "core/errors.h"
#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "core/port_types/keypoints.h"
#include "support/host_poll.h"

using namespace std::chrono_literals;

namespace {
const std::string kSrc = CREASE_SOURCE_DIR;

struct Fixture {
  crease::PluginHost host{{CREASE_PLUGIN_DIR}};
  std::unique_ptr<crease::Keypoints> kp = std::make_unique<crease::Keypoints>();
  Fixture() { host.add_loop({"vision", 30.0, 0, -1}); }
  // Relative paths resolve against config/ (the file named here).
  void add(const std::string& name, const std::string& library, int order,
           const std::string& yaml) {
    crease::InstanceSpec s;
    s.name = name;
    s.library = library;
    s.loop = "vision";
    s.order = order;
    s.params = crease::Params(YAML::Load(yaml), kSrc + "/config/test.yaml", name + ".params");
    host.add_instance(s);
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
