#include "plugins/camera_rig/calibration.h"

#include <doctest/doctest.h>

#include "plugins/sim_world/scene/sheet_mesh.h"
#include "plugins/sim_world/scene/view_renderer.h"

using namespace crease::vision;

namespace {
// The board as a flat "sheet" lying face up where the board's world frame says it is.
SheetMesh board_mesh(const CharucoSpec& s) {
  const double w = s.squares_x * s.square_mm, h = s.squares_y * s.square_mm;
  const bool flipped = board_to_world(s)(1, 1) < 0;  // board y runs down the printed face
  return flat_sheet(8, 6, w, h, {w / 2, flipped ? -h / 2 : h / 2, 0}, 0.0);
}

Camera with_intrinsics(Camera c) {
  c.dist = {-0.12, 0.08, 0.0006, -0.0004, 0, 0, 0, 0};
  c.K(0, 2) += 4;
  c.K(1, 2) -= 3;
  return c;
}
}  // namespace

TEST_CASE("ChArUco intrinsics from rendered views recover focal length, centre and distortion") {
  CharucoSpec s;
  const double ppm = 8;
  const cv::Mat tex = draw_charuco(s, ppm);
  const double w = s.squares_x * s.square_mm, h = s.squares_y * s.square_mm;
  const cv::Vec3d target = board_to_world(s) * cv::Vec3d(w / 2, h / 2, 0);
  std::vector<Camera> views;
  const cv::Vec3d eyes[] = {{0, 0, 420}, {180, 60, 380}, {-170, -40, 390}, {60, 200, 360},
                            {-50, -220, 370}, {220, -150, 330}, {-200, 180, 350}, {30, -30, 300}};
  for (int i = 0; i < 8; ++i)
    views.push_back(with_intrinsics(look_at_camera("c", 640, 480, 700, target + eyes[i], target + cv::Vec3d(i * 6.0 - 20, 0, 0))));
  const ViewRenderer r(tex, tex, ppm, views);
  std::vector<cv::Mat> imgs;
  for (int i = 0; i < 8; ++i) {
    RenderedView v;
    r.render(i, board_mesh(s), RenderOptions{.seed = static_cast<std::uint64_t>(i)}, v);
    imgs.push_back(v.image);
  }
  const IntrinsicsResult res = calibrate_intrinsics(imgs, s);
  MESSAGE("rms " << res.rms_px << " px over " << res.views_used << " views, fx " << res.camera.K(0, 0) << " k1 "
                 << res.camera.dist[0]);
  CHECK(res.views_used >= 6);
  CHECK(res.rms_px < 0.5);
  CHECK(res.camera.K(0, 0) == doctest::Approx(700).epsilon(0.01));
  CHECK(res.camera.K(1, 1) == doctest::Approx(700).epsilon(0.01));
  CHECK(std::abs(res.camera.K(0, 2) - views[0].K(0, 2)) < 4);
  CHECK(std::abs(res.camera.K(1, 2) - views[0].K(1, 2)) < 4);
  CHECK(res.camera.dist[0] == doctest::Approx(-0.12).epsilon(0.25));
  CHECK_THROWS_AS(calibrate_intrinsics({imgs[0], imgs[1]}, s), std::runtime_error);
}

TEST_CASE("shared-board extrinsics put every rig camera where it is") {
  CharucoSpec s;
  const double ppm = 8;
  const cv::Mat tex = draw_charuco(s, ppm);
  const double w = s.squares_x * s.square_mm, h = s.squares_y * s.square_mm;
  const cv::Vec3d centre = board_to_world(s) * cv::Vec3d(w / 2, h / 2, 0);
  // The default rig, moved so that it looks at the board's centre.
  std::vector<Camera> rig = default_rig();
  for (auto& c : rig) c.t = c.t - c.R * centre;
  const ViewRenderer r(tex, tex, ppm, rig);
  for (int k = 0; k < static_cast<int>(rig.size()); ++k) {
    RenderedView v;
    r.render(k, board_mesh(s), RenderOptions{.seed = 9}, v);
    Camera est = rig[static_cast<std::size_t>(k)];
    est.R = cv::Matx33d::eye();
    est.t = cv::Vec3d(0, 0, 0);
    double rms = 0;
    REQUIRE(board_extrinsics(v.image, s, est, &rms));
    const Camera& truth = rig[static_cast<std::size_t>(k)];
    const double angle_deg = std::acos(std::clamp((cv::trace(est.R.t() * truth.R) - 1) / 2, -1.0, 1.0)) * 180 / CV_PI;
    MESSAGE("camera " << k << ": centre error " << cv::norm(est.centre_world() - truth.centre_world()) << " mm, "
                      << angle_deg << " deg, rms " << rms << " px");
    CHECK(cv::norm(est.centre_world() - truth.centre_world()) < 3.0);
    CHECK(angle_deg < 0.3);
    CHECK(rms < 0.5);
  }
}
