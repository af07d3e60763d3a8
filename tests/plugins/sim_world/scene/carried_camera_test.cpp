// Cameras the robot carries (plugins/sim_world/scene/carried_camera.h, DepthSimSource with the
// shipped D405-like wrist calibrations, config/wrist_cameras): the mount shape found by side, role
// and index; a wrist camera whose hand moves renders the sheet from the moved pose (a flat sheet
// back-projects to its plane within the noise model's figure from two poses, and not with the pose
// it had before); its frames are empty and counted while the world's shapes hold no mount; a shape
// is drawn only in front of the camera's near plane; on the shipped robot the mounts are the
// forearms' capsules and the right camera sees its hand and the sheet beyond it.
#include "plugins/sim_world/scene/carried_camera.h"

#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "plugins/sim_world/robot_shapes.h"
#include "plugins/sim_world/scene/depth_sim_source.h"
#include "tests/plugins/sim_world/scene.h"
#include "tests/plugins/sim_world/scene/forearm_rig.h"

using namespace crease::vision;
using namespace forearm_rig;  // Role, looking_down, shape, set_pose, forearm_carrying, d405

namespace {
const std::string kSrc = CREASE_SOURCE_DIR;
constexpr double kSheetZ = 0.5;  // a flat sheet's surface, world mm (half its 1 mm thickness)

struct PlaneFit {
  int points = 0;
  double rms = 0, mean = 0, expected = 0;  // mm: residuals from z = kSheetZ; the model's figure
};

// The sheet's pixels (blue, with depth) of DEPTH / BGR back-projected with the world -> camera pose
// (R, t) of a camera with CAM's intrinsics, against the plane z = kSheetZ.
PlaneFit plane_fit(const DepthCamera& cam, const cv::Mat& depth, const cv::Mat& bgr,
                   const cv::Matx33d& R, const cv::Vec3d& t, const DepthSensorModel& sm) {
  const cv::Mat rays = ray_table(cam.camera);
  PlaneFit f;
  double sum = 0, sum2 = 0, var = 0;
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) {
      const auto d = depth.at<std::uint16_t>(y, x);
      const cv::Vec3b c = bgr.at<cv::Vec3b>(y, x);
      if (d == 0 || c[0] < c[2] + 60) continue;  // no depth, or not the blue sheet
      const double z = d * cam.depth_unit_mm;
      const cv::Vec2f r = rays.at<cv::Vec2f>(y, x);
      const cv::Vec3d w = R.t() * (cv::Vec3d(r[0] * z, r[1] * z, z) - t);
      sum += w[2] - kSheetZ;
      sum2 += (w[2] - kSheetZ) * (w[2] - kSheetZ);
      const double s = depth_sigma_mm(sm, cam.camera.mean_focal_px(), z);
      var += s * s;
      ++f.points;
    }
  if (f.points == 0) return f;
  f.mean = sum / f.points;
  f.rms = std::sqrt(sum2 / f.points);
  f.expected = std::sqrt(var / f.points + cam.depth_unit_mm * cam.depth_unit_mm / 12);
  return f;
}

}  // namespace

TEST_CASE("mount_shape_index: the index-th shape of that role on that side, in the port's order") {
  const auto k = crease::world::GeomKind::sphere;
  const std::vector<SceneShape> shapes = {
      shape(k, 1, 0, Role::arm, 0),  shape(k, 1, 0, Role::hand, 1), shape(k, 1, 0, Role::hand, 0),
      shape(k, 1, 0, Role::palm, 0), shape(k, 1, 0, Role::hand, 0), shape(k, 1, 0, Role::hand, 1)};
  CHECK(mount_shape_index(shapes, {0, Role::hand, 0}) == 2);
  CHECK(mount_shape_index(shapes, {0, Role::hand, 1}) == 4);
  CHECK(mount_shape_index(shapes, {1, Role::hand, 1}) == 5);
  CHECK(mount_shape_index(shapes, {0, Role::palm, 0}) == 3);
  CHECK(mount_shape_index(shapes, {0, Role::hand, 2}) == -1);  // fewer of them
  CHECK(mount_shape_index(shapes, {1, Role::palm, 0}) == -1);  // none on that side
  CHECK(mount_shape_index({}, {0, Role::hand, 0}) == -1);      // nothing received yet
}

TEST_CASE("a wrist camera whose hand moves renders the flat sheet from the moved pose") {
  const auto wrist = load_depth_camera_dir(kSrc + "/config/wrist_cameras");
  REQUIRE(wrist[0].mount.has_value());
  const DepthCamera& cam = wrist[0];
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  const cv::Mat tex = DepthSimSource::plain_texture(400, 400, 1.0);
  // Two poses of the right forearm: the camera 300 mm over the sheet's centre looking down; then
  // 220 mm up, 30 mm right and 40 mm nearer the robot, tilted 20 deg.
  const cv::Matx33d R_a = looking_down(0), R_b = looking_down(20);
  const cv::Vec3d c_a(0, 0, 300), c_b(30, -40, 220);
  std::vector<SceneShape> shapes = forearm_carrying(cam.camera, R_a, c_a);
  const DepthSensorModel sm = d405();
  DepthSimSource src(
      {cam}, tex, tex, 1.0, [&](std::uint64_t) { return flat; }, RenderOptions{}, sm,
      DepthColourModel{}, 33'000'000);
  src.set_shapes_source([&](std::vector<SceneShape>& out) { out = shapes; });
  Frame fa, fb;
  const auto t0 = std::chrono::steady_clock::now();
  REQUIRE(src.grab(fa));
  const auto t1 = std::chrono::steady_clock::now();
  shapes = forearm_carrying(cam.camera, R_b, c_b);
  REQUIRE(src.grab(fb));
  MESSAGE(
      "one 848x480 wrist camera frame (first, with the buffers' allocation): "
      << std::chrono::duration<double, std::milli>(t1 - t0).count() << " ms; the next: "
      << std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count()
      << " ms");
  REQUIRE(!fa.images[0].empty());
  REQUIRE(!fb.images[0].empty());
  CHECK(src.carried_frames() == 2);
  CHECK(src.carried_unposed() == 0);
  const auto t_of = [](const cv::Matx33d& R, const cv::Vec3d& c) { return cv::Vec3d(-(R * c)); };
  const PlaneFit a = plane_fit(cam, fa.images[0], fa.images[1], R_a, t_of(R_a, c_a), sm);
  const PlaneFit b = plane_fit(cam, fb.images[0], fb.images[1], R_b, t_of(R_b, c_b), sm);
  // Frame b taken for one from the pose the camera had before: what a world-fixed camera assumes.
  const PlaneFit stale = plane_fit(cam, fb.images[0], fb.images[1], R_a, t_of(R_a, c_a), sm);
  MESSAGE("pose a: " << a.points << " sheet points, plane rms " << a.rms << " mm (model "
                     << a.expected << "), mean " << a.mean << "; pose b: " << b.points << ", rms "
                     << b.rms << " (model " << b.expected << "), mean " << b.mean
                     << "; b with pose a: rms " << stale.rms);
  for (const PlaneFit* f : {&a, &b}) {
    REQUIRE(f->points > 20000);
    // Noise along the ray (the plane's normal within 20 deg of the axis: cos 20 = 0.94 of it seen
    // along the normal) and the mean over a finite sample.
    CHECK(f->rms <= 1.1 * f->expected);
    CHECK(f->rms >= 0.8 * f->expected);
    CHECK(std::abs(f->mean) < 0.1);
  }
  CHECK(a.expected <
        1.0);  // D405 at ~0.3 m: sigma 0.9 mm (0.3 % of the range; Intel: < 2 % at 0.5 m)
  CHECK(b.expected < a.expected);
  CHECK(stale.rms > 20 * b.expected);  // a camera that did not move with its hand is far off
  CHECK(cv::norm(fa.images[0], fb.images[0], cv::NORM_L1) > 0);
  // The depth in the D405's 0.1 mm unit, within its range.
  double mn = 1e9, mx = 0;
  cv::minMaxLoc(fa.images[0], nullptr, &mx);
  for (int y = 0; y < fa.images[0].rows; ++y)
    for (int x = 0; x < fa.images[0].cols; ++x)
      if (const auto d = fa.images[0].at<std::uint16_t>(y, x); d != 0) mn = std::min<double>(mn, d);
  CHECK(mn * 0.1 >= 70);
  CHECK(mx * 0.1 <= 500);
}

TEST_CASE("a wrist camera with no mount shape in the world's shapes delivers nothing, counted") {
  const auto wrist = load_depth_camera_dir(kSrc + "/config/wrist_cameras");
  const auto fixed = load_depth_camera_dir(kSrc + "/config/depth_cameras");
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  const cv::Mat tex = DepthSimSource::plain_texture(400, 400, 1.0);
  std::vector<SceneShape> shapes;  // none received yet
  DepthSimSource src(
      {fixed[0], wrist[0], wrist[1]}, tex, tex, 1.0, [&](std::uint64_t) { return flat; },
      RenderOptions{}, d405(), DepthColourModel{}, 33'000'000);
  src.set_shapes_source([&](std::vector<SceneShape>& out) { out = shapes; });
  CHECK(src.any_carried());
  Frame f;
  REQUIRE(src.grab(f));
  REQUIRE(f.images.size() == 6);
  CHECK(!f.images[0].empty());  // the fixed camera goes on
  CHECK(!f.images[1].empty());
  for (std::size_t k = 2; k < 6; ++k) CHECK(f.images[k].empty());
  CHECK(src.carried_frames() == 2);
  CHECK(src.carried_unposed() == 2);
  // The right forearm only: the right camera delivers, the left still does not.
  shapes = forearm_carrying(wrist[0].camera, looking_down(0), {0, 0, 300});
  REQUIRE(src.grab(f));
  CHECK(!f.images[2].empty());
  CHECK(!f.images[3].empty());
  CHECK(f.images[4].empty());
  CHECK(src.carried_frames() == 4);
  CHECK(src.carried_unposed() == 3);
  // The right forearm's capsule missing (only its cylinder, hand #0): nothing from the right
  // either.
  shapes.resize(1);
  REQUIRE(src.grab(f));
  CHECK(f.images[2].empty());
  CHECK(src.carried_unposed() == 5);
}

TEST_CASE("a carried camera draws a shape only in front of its near plane, none it sits in") {
  const auto wrist = load_depth_camera_dir(kSrc + "/config/wrist_cameras");
  const Camera& cam = wrist[0].camera;
  const cv::Matx33d R = looking_down(0);
  const cv::Vec3d c(0, 0, 300);
  std::vector<SceneShape> shapes = forearm_carrying(cam, R, c);
  Camera posed = cam;
  REQUIRE(place_carried_camera(cam, *wrist[0].mount, shapes, posed));
  CHECK(cv::norm(posed.centre_world() - c) < 1e-9);
  CHECK(cv::norm(posed.R - R) < 1e-12);
  const auto world = [&](const cv::Vec3d& in_cam) { return c + R.t() * in_cam; };
  // A sphere the camera sits in (its centre 5 mm behind the camera, radius 15 mm) and a box that
  // straddles the camera's plane below the optical axis (camera z from -60 to 60 mm).
  SceneShape inside = shape(crease::world::GeomKind::sphere, 15, 0, Role::fingertip, 0);
  set_pose(inside, R.t(), world({0, 0, -5}));
  SceneShape box = shape(crease::world::GeomKind::box, 0, 0, Role::finger, 0);
  box.geom.half_mm = {30, 15, 60};
  set_pose(box, R.t(), world({0, 25, 0}));
  shapes.push_back(inside);
  shapes.push_back(box);
  const cv::Mat tex = DepthSimSource::plain_texture(400, 400, 1.0);
  ViewRenderer renderer(tex, tex, 1.0, {cam});
  renderer.set_pose(0, posed.R, posed.t);
  RenderOptions ro;
  ro.shape_lattice_px = 1;
  RenderedView view;
  renderer.render(0, flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ}), ro, view, shapes);
  REQUIRE(!view.shape_depth.empty());
  int drawn = 0;
  double z_min = 1e9, z_max = 0;
  for (int y = 0; y < view.shape_depth.rows; ++y)
    for (int x = 0; x < view.shape_depth.cols; ++x)
      if (const float z = view.shape_depth.at<float>(y, x); std::isfinite(z)) {
        ++drawn;
        z_min = std::min<double>(z_min, z);
        z_max = std::max<double>(z_max, z);
      }
  MESSAGE("shape pixels " << drawn << ", camera z " << z_min << " to " << z_max << " mm");
  CHECK(drawn > 1000);   // the box's part in front of the camera
  CHECK(z_min >= 1.0);   // nothing at or behind the near plane (1 mm)
  CHECK(z_max <= 60.5);  // up to the box's front (60 mm): no part of the sphere
  // The optical axis sees the sheet through the sphere the camera sits in.
  const cv::Point centre(424, 240);
  CHECK(!std::isfinite(view.shape_depth.at<float>(centre)));
  CHECK(view.depth.at<float>(centre) == doctest::Approx(300 - kSheetZ).epsilon(1e-3));
}

TEST_CASE(
    "the shipped wrist cameras on the shipped robot: on the forearms' capsules, seeing the sheet") {
  using scene::Vec3;
  const auto wrist = load_depth_camera_dir(kSrc + "/config/wrist_cameras");
  // The right hand hanging over the sheet, fingers down (the palm link's z), palm facing forward
  // (+y: the palm link's -y), its palm's front 230 mm above the table; the left arm parked.
  scene::Rig rig(crease::world::WorldParams{}, "palmfront", Vec3{0, -60, 230},
                 scene::frame_from_z_x(Vec3{0, 0, -1}, Vec3{1, 0, 0}), scene::index_out());
  auto port = std::make_unique<crease::WorldShapes>();
  crease::world::export_shapes_rt(rig.world->shapes(), *port);
  std::vector<SceneShape> shapes;
  shapes_of(*port, shapes);
  // Each calibration's mount is its side's forearm capsule (radius 45 mm, 110 mm between its caps).
  for (std::size_t k = 0; k < wrist.size(); ++k) {
    CAPTURE(k);
    const int i = mount_shape_index(shapes, *wrist[k].mount);
    REQUIRE(i >= 0);
    const SceneShape& s = shapes[static_cast<std::size_t>(i)];
    CHECK(s.geom.kind == crease::world::GeomKind::capsule);
    CHECK(s.geom.radius_mm == doctest::Approx(45));
    CHECK(s.geom.half_length_mm == doctest::Approx(55));
    CHECK(s.side == k);
  }
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  const cv::Mat tex = DepthSimSource::plain_texture(400, 400, 1.0);
  const DepthSensorModel sm = d405();
  DepthSimSource src(
      {wrist[0]}, tex, tex, 1.0, [&](std::uint64_t) { return flat; }, RenderOptions{}, sm,
      DepthColourModel{}, 33'000'000);
  src.set_shapes_source([&](std::vector<SceneShape>& out) { out = shapes; });
  Frame f;
  REQUIRE(src.grab(f));
  REQUIRE(!f.images[0].empty());
  Camera posed = wrist[0].camera;
  REQUIRE(place_carried_camera(wrist[0].camera, *wrist[0].mount, shapes, posed));
  const PlaneFit fit = plane_fit(wrist[0], f.images[0], f.images[1], posed.R, posed.t, sm);
  int skin = 0, skin_top = 0;  // the hand's skin colour (red over blue); in the image's top half
  for (int y = 0; y < f.images[1].rows; ++y)
    for (int x = 0; x < f.images[1].cols; ++x) {
      const cv::Vec3b c = f.images[1].at<cv::Vec3b>(y, x);
      skin += c[2] > c[0] + 20;
      skin_top += c[2] > c[0] + 20 && y < f.images[1].rows / 2;
    }
  const cv::Vec3d c = posed.centre_world();
  MESSAGE("right wrist camera at (" << c[0] << ", " << c[1] << ", " << c[2] << ") mm: "
                                    << fit.points << " sheet points, plane rms " << fit.rms
                                    << " mm (model " << fit.expected << "); skin pixels " << skin);
  CHECK(fit.points > 20000);
  CHECK(fit.rms <= 1.1 * fit.expected);
  CHECK(std::abs(fit.mean) < 0.2);
  // Its own palm and fingers in the lower part of the image, the sheet beyond them.
  CHECK(skin > 10000);
  CHECK(skin_top == 0);
}
