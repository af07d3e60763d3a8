// The simulated cameras' source: every camera renders the mesh of its frame, stamped with the
// mesh's own time when it has one; a frame given buffers is rendered into them. The sheet of a
// SheetState (what camera_sim reads from `sheet_truth`) becomes the mesh, and a state never
// written becomes no sheet at all: the cameras see the empty table.
#include "plugins/sim_world/scene/sim_source.h"

#include <doctest/doctest.h>

#include <limits>
#include <memory>
#include <vector>

#include "core/port_types/sheet_state.h"
#include "plugins/sim_world/scene/marker_scene.h"

using namespace crease::vision;

namespace {
// One camera of the seed-000 rig, so that each frame is one render.
std::shared_ptr<const ViewRenderer> one_camera(const testing::Scene& s) {
  return std::make_shared<const ViewRenderer>(
      face_texture(s.layout, Face::kFront, testing::Scene::kTexPpm),
      face_texture(s.layout, Face::kBack, testing::Scene::kTexPpm), testing::Scene::kTexPpm,
      std::vector<Camera>{default_rig()[0]});
}
int sheet_pixels(const RenderedView& v) {  // pixels where the sheet is in front of the camera
  return cv::countNonZero(v.depth < std::numeric_limits<float>::infinity());
}
}  // namespace

TEST_CASE("frames: the mesh's time when it has one, else start + index * period") {
  const testing::Scene s;
  SheetMesh timed = s.flat();
  timed.timestamp_ns = 123'456;
  bool use_timed = false;
  SimSource src(
      one_camera(s), [&](std::uint64_t) { return use_timed ? timed : s.flat(); }, RenderOptions{},
      1'000, 50'000);
  Frame f;
  REQUIRE(src.grab(f));
  CHECK(f.index == 0);
  CHECK(f.timestamp_ns == 50'000);
  REQUIRE(src.grab(f));
  CHECK(f.index == 1);
  CHECK(f.timestamp_ns == 51'000);
  use_timed = true;
  REQUIRE(src.grab(f));
  CHECK(f.index == 2);
  CHECK(f.timestamp_ns == 123'456);
  REQUIRE(f.images.size() == 1);
  CHECK(f.images[0].cols == default_rig()[0].width);
  CHECK(f.images[0].type() == CV_8UC1);
}

TEST_CASE("a frame given buffers is rendered into them") {
  const testing::Scene s;
  SimSource src(
      one_camera(s), [&](std::uint64_t) { return s.flat(); }, RenderOptions{}, 1'000);
  const Camera cam = default_rig()[0];
  cv::Mat buffer(cam.height, cam.width, CV_8UC1, cv::Scalar(7));
  Frame f;
  f.images = {buffer};
  f.fill_in_place = true;
  REQUIRE(src.grab(f));
  CHECK(f.images[0].data == buffer.data);    // the caller's pixels
  CHECK(cv::countNonZero(buffer != 7) > 0);  // rendered over
}

TEST_CASE("a SheetState's sheet becomes the mesh; a state never written gives no sheet") {
  const testing::Scene s;
  auto state = std::make_unique<crease::SheetState>();
  RenderOptions ro;
  ro.occluders = 2;  // hands are drawn over a sheet only
  RenderedView view;

  // Never written (0 x 0 nodes): an empty mesh, nothing but the table in view.
  const SheetMesh none = mesh_of(*state);
  CHECK(none.nx == 0);
  CHECK(none.nodes.empty());
  s.renderer->render(0, none, ro, view);
  CHECK(sheet_pixels(view) == 0);
  CHECK(cv::countNonZero(view.occluder_mask) == 0);

  // The flat sheet written into the state: the same mesh, with the state's time.
  const SheetMesh flat = s.flat();
  state->nodes_u = static_cast<std::uint16_t>(flat.nx);
  state->nodes_v = static_cast<std::uint16_t>(flat.ny);
  state->width_mm = static_cast<float>(flat.w_mm);
  state->height_mm = static_cast<float>(flat.h_mm);
  state->timestamp_ns = 42;
  for (std::size_t k = 0; k < flat.nodes.size(); ++k)
    for (int c = 0; c < 3; ++c) state->position_mm[k][c] = static_cast<float>(flat.nodes[k][c]);
  const SheetMesh m = mesh_of(*state);
  REQUIRE(m.nx == flat.nx);
  REQUIRE(m.ny == flat.ny);
  CHECK(m.timestamp_ns == 42);
  CHECK(cv::norm(m.node(flat.nx - 1, flat.ny - 1) - flat.node(flat.nx - 1, flat.ny - 1)) < 1e-3);
  s.renderer->render(0, m, ro, view);
  CHECK(sheet_pixels(view) > 10000);
  CHECK(cv::countNonZero(view.occluder_mask) > 0);
}

TEST_CASE("a camera dropout delivers nothing for its frames, and only for them; the draws are the seed's") {
  const testing::Scene s;
  SimSource src(
      one_camera(s), [&](std::uint64_t) { return s.flat(); }, RenderOptions{}, 1'000, 0, {{0, 2, 3}});
  for (std::uint64_t i = 0; i < 7; ++i) {
    Frame f;
    REQUIRE(src.grab(f));
    REQUIRE(f.images.size() == 1);
    INFO("frame " << i);
    CHECK(f.images[0].empty() == (i >= 2 && i < 5));
  }
  const auto a = draw_dropouts(4, 3, 8, 30, 450, 5), b = draw_dropouts(4, 3, 8, 30, 450, 5);
  REQUIRE(a.size() == 3);
  for (std::size_t k = 0; k < a.size(); ++k) {
    CHECK(a[k].camera == b[k].camera);
    CHECK(a[k].first_frame == b[k].first_frame);
    CHECK(a[k].camera >= 0);
    CHECK(a[k].camera < 5);
    CHECK(a[k].first_frame >= 30);
    CHECK(a[k].first_frame <= 450);
    CHECK(a[k].frames == 8);
  }
  CHECK(draw_dropouts(4, 0, 8, 30, 450, 5).empty());
}
