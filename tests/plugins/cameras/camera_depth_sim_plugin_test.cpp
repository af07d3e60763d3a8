// camera_depth_sim in a loop with `world_shapes: true`: the world's shapes of that port are taken
// every cycle and rendered by the worker (their depth: tests/plugins/sim_world/scene/
// depth_view_test.cpp); frame sets keep coming from both cameras and the update allocates nothing.
#include <doctest/doctest.h>

#include <chrono>
#include <memory>
#include <string>

#include "core/plugin_host.h"
#include "core/port_types/camera_frames.h"
#include "core/port_types/world_shapes.h"
#include "support/host_poll.h"
#include "support/instance_spec.h"

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
  for (const auto& i : host.instances()) {
    CAPTURE(i.name);
    CHECK(i.state == crease::RunState::active);
    CHECK(i.stats->updates.load() > 0);
    CHECK(i.stats->rt_allocations.load() == 0);
  }
  host.stop();
}
