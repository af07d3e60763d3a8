// The simulated RGB-D cameras (plugins/sim_world/scene/depth_view.h, depth_sim_source.h) with
// the shipped D435 calibrations (config/depth_cameras): a flat plain sheet back-projects to its
// plane within the noise model's figure; the colour mask keeps >= 99 % of the sheet's pixels
// with depth and no pixel of a hand; no depth at grazing angles (and depth there once the
// grazing limit is lifted); the depth image is in the calibration's unit; the world's shapes at
// their own depth over the sheet and hidden under it.
#include "plugins/sim_world/scene/depth_sim_source.h"

#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "plugins/depth_tracking/point_cloud.h"

using namespace crease::vision;

namespace {
const std::string kSrc = CREASE_SOURCE_DIR;
constexpr double kSheetZ = 0.5;  // a flat sheet's surface, world mm (half its 1 mm thickness)

crease::depth::CloudParams blue_mask() {
  crease::depth::CloudParams p;
  p.mask = {95, 115, 120, 255, 40, 255};  // the default plain sheet (BGR 200 140 40: h ~ 102)
  p.voxel_mm = 1.0;
  return p;
}

struct Shot {
  cv::Mat depth, bgr;
  RenderedView view;
};

Shot shoot(const DepthCamera& cam, const SheetMesh& mesh, int occluders, DepthSensorModel sm = {},
           const std::vector<SceneShape>& shapes = {}) {
  const cv::Mat tex = DepthSimSource::plain_texture(400, 400, 1.0);
  ViewRenderer r(tex, tex, 1.0, {cam.camera});
  Shot s;
  RenderOptions ro;
  ro.occluders = occluders;
  ro.shape_lattice_px = 1;  // as DepthSimSource renders: the shapes' depth exact
  r.render(0, mesh, ro, s.view, shapes);
  make_depth_view(cam.camera, ray_table(cam.camera), cam.depth_unit_mm, s.view, sm, DepthColourModel{}, 7,
                  s.depth, s.bgr);
  return s;
}
}  // namespace

TEST_CASE("a flat plain sheet seen by the overhead D435 back-projects to its plane within sigma(z)") {
  const auto cams = load_depth_camera_dir(kSrc + "/config/depth_cameras");
  REQUIRE(cams.size() == 2);
  CHECK(cams[0].camera.width == 848);
  CHECK(cams[0].camera.height == 480);
  CHECK(cams[0].depth_unit_mm == 1.0);
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  const Shot s = shoot(cams[0], flat, 0);
  crease::depth::CloudBuilder cb;
  cb.configure(blue_mask(), {cams[0].camera}, 848 * 480);
  REQUIRE(cb.add_view(0, s.depth, s.bgr));
  // The plane's residuals against the model's sigma at the sheet's distance from the camera.
  double sum2 = 0, z_cam = 0;
  int n = 0;
  for (const auto& p : cb.points()) {
    sum2 += (p[2] - kSheetZ) * (p[2] - kSheetZ);
    z_cam += cams[0].camera.to_camera({p[0], p[1], p[2]})[2];
    ++n;
  }
  REQUIRE(n > 10000);
  z_cam /= n;
  const double sigma = depth_sigma_mm(DepthSensorModel{}, cams[0].camera.mean_focal_px(), z_cam);
  const double rms = std::sqrt(sum2 / n);
  MESSAGE("sheet points " << n << " at z_cam " << z_cam << " mm: plane rms " << rms << " mm, model sigma "
                          << sigma << " mm (depth z, the plane's normal is ~the optical axis)");
  // Noise along the ray, seen along the plane's normal (~5 deg off the axis), plus quantisation
  // (1 mm / sqrt(12)) and the mean over a finite sample.
  const double expect = std::sqrt(sigma * sigma + 1.0 / 12.0);
  CHECK(rms == doctest::Approx(expect).epsilon(0.1));
  CHECK(sigma > 1.4);  // the D435 figure at ~0.65 m: 1.6 mm (not a noiseless camera)
  // Quantised to the unit: integer counts, all of them within the camera's range.
  double mn = 1e9, mx = 0;
  for (int y = 0; y < s.depth.rows; ++y)
    for (int x = 0; x < s.depth.cols; ++x)
      if (const auto d = s.depth.at<std::uint16_t>(y, x); d != 0) {
        mn = std::min<double>(mn, d);
        mx = std::max<double>(mx, d);
      }
  CHECK(mn >= 200);
  CHECK(mx <= 3000);
}

TEST_CASE("the colour mask keeps >= 99 % of the sheet's pixels with depth and no hand pixel") {
  const auto cams = load_depth_camera_dir(kSrc + "/config/depth_cameras");
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  for (std::size_t k = 0; k < cams.size(); ++k) {
    CAPTURE(k);
    const Shot s = shoot(cams[k], flat, 2);
    int sheet_px = 0, sheet_kept = 0, hand_px = 0, hand_kept = 0;
    const auto mask = blue_mask().mask;
    for (int y = 0; y < s.depth.rows; ++y)
      for (int x = 0; x < s.depth.cols; ++x) {
        const cv::Vec3b c = s.bgr.at<cv::Vec3b>(y, x);
        int h, sat, v;
        crease::depth::bgr_to_hsv(c[0], c[1], c[2], h, sat, v);
        const bool kept = mask.contains(h, sat, v);
        if (s.view.occluder_mask.at<std::uint8_t>(y, x) != 0) {
          ++hand_px;
          hand_kept += kept;
        } else if (std::isfinite(s.view.depth.at<float>(y, x)) && s.depth.at<std::uint16_t>(y, x) != 0) {
          ++sheet_px;
          sheet_kept += kept;
        }
      }
    MESSAGE("camera " << k << ": sheet pixels " << sheet_px << ", kept " << sheet_kept << "; hand pixels " << hand_px
                      << ", kept " << hand_kept);
    REQUIRE(sheet_px > 5000);
    REQUIRE(hand_px > 500);  // the hands are in view
    CHECK(sheet_kept >= 0.99 * sheet_px);
    CHECK(hand_kept == 0);
  }
}

TEST_CASE(
    "the world's shapes at their own depth: a fingertip over the sheet, the sheet beside it; none "
    "under it") {
  const auto cams = load_depth_camera_dir(kSrc + "/config/depth_cameras");
  const Camera& cam = cams[0].camera;  // overhead
  DepthSensorModel sm;
  sm.noise = false;  // exact depth, quantised to the 1 mm unit
  // A fingertip (sphere r 8 mm) 40 mm over the sheet lying on the table, and the sheet 50 mm beside
  // it.
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  SceneShape tip;
  tip.geom.kind = crease::world::GeomKind::sphere;
  tip.geom.radius_mm = 8;
  tip.pose.t = {0, 0, 40};
  const Shot s = shoot(cams[0], flat, 0, sm, {tip});
  const auto pixel = [&](cv::Vec3d w) {
    cv::Point2d px;
    REQUIRE(cam.project(w, px));
    return cv::Point(static_cast<int>(std::lround(px.x)), static_cast<int>(std::lround(px.y)));
  };
  // Along the ray to the sphere's point nearest the camera.
  const cv::Vec3d centre(0, 0, 40), to_cam = cv::normalize(cam.centre_world() - centre);
  const cv::Vec3d near_point = centre + 8.0 * to_cam;
  const cv::Point p_tip = pixel(near_point), p_sheet = pixel({50, 0, kSheetZ});
  const double z_tip = cam.to_camera(near_point)[2], z_sheet = cam.to_camera({50, 0, kSheetZ})[2];
  CAPTURE(z_tip);
  CAPTURE(z_sheet);
  CHECK(std::abs(s.depth.at<std::uint16_t>(p_tip) - z_tip) <= 1.0);
  CHECK(std::abs(s.depth.at<std::uint16_t>(p_sheet) - z_sheet) <= 1.0);
  CHECK(z_sheet - z_tip > 30.0);  // the two are told apart
  // Skin where the fingertip is (red over blue), the blue sheet beside it.
  const cv::Vec3b c_tip = s.bgr.at<cv::Vec3b>(p_tip), c_sheet = s.bgr.at<cv::Vec3b>(p_sheet);
  CHECK(c_tip[2] > c_tip[0]);
  CHECK(c_sheet[0] > c_sheet[2]);
  // The sheet held 60 mm up, the fingertip under it: the depth image is the sheet's alone.
  const SheetMesh raised = flat_sheet(15, 21, 210, 297, {0, 0, 60});
  const Shot plain = shoot(cams[0], raised, 0, sm), under = shoot(cams[0], raised, 0, sm, {tip});
  CHECK(cv::countNonZero(under.view.occluder_mask) == 0);
  CHECK(cv::norm(plain.depth, under.depth, cv::NORM_INF) == 0);
}

TEST_CASE("no depth at grazing angles: a sheet seen edge-on has none until the limit is lifted") {
  const auto cams = load_depth_camera_dir(kSrc + "/config/depth_cameras");
  // The overhead camera looks down; a flap folded to 90 deg about the middle stands vertical.
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  const SheetMesh edge_on = fold_sheet(flat, 297.0 / 2, CV_PI / 2);
  const auto standing = [&](const Shot& s) {  // pixels with depth above the lying half
    int n = 0;
    for (int y = 0; y < s.depth.rows; ++y)
      for (int x = 0; x < s.depth.cols; ++x) {
        const float z = s.view.depth.at<float>(y, x);
        const auto d = s.depth.at<std::uint16_t>(y, x);
        // Rendered sheet more than 20 mm above the table (the standing flap) and measured.
        if (std::isfinite(z) && d != 0) {
          const double table_z = cams[0].camera.to_camera({0, 0, 0})[2];
          if (z < table_z - 20) ++n;
        }
      }
    return n;
  };
  DepthSensorModel sm;
  sm.noise = false;
  const int grazing_off = standing(shoot(cams[0], edge_on, 0, sm));
  sm.max_incidence_deg = 90.0;
  sm.edge_jump_mm = 1e4;
  const int grazing_on = standing(shoot(cams[0], edge_on, 0, sm));
  MESSAGE("flap pixels with depth: " << grazing_off << " with the grazing limit, " << grazing_on << " without");
  CHECK(grazing_on > 20);
  CHECK(grazing_off < grazing_on / 4);
}

TEST_CASE("DepthSimSource: frames of depth and colour in the channel's order, deterministic for a seed") {
  const auto cams = load_depth_camera_dir(kSrc + "/config/depth_cameras");
  const cv::Mat tex = DepthSimSource::plain_texture(400, 400, 1.0);
  const SheetMesh flat = flat_sheet(15, 21, 210, 297, {0, 0, kSheetZ});
  const auto make = [&] {
    return DepthSimSource(cams, tex, tex, 1.0, [&](std::uint64_t) { return flat; }, RenderOptions{},
                          DepthSensorModel{}, DepthColourModel{}, 33'000'000);
  };
  DepthSimSource a = make(), b = make();
  const auto specs = a.channel_images();
  REQUIRE(specs.size() == 4);
  CHECK(specs[0].name == "cam0.depth");
  CHECK(specs[0].bytes_per_pixel == 2);
  CHECK(specs[1].name == "cam0.colour");
  CHECK(specs[1].bytes_per_pixel == 3);
  Frame fa, fb;
  REQUIRE(a.grab(fa));
  REQUIRE(b.grab(fb));
  REQUIRE(fa.images.size() == 4);
  CHECK(fa.images[0].type() == CV_16UC1);
  CHECK(fa.images[1].type() == CV_8UC3);
  CHECK(fa.images[2].cols == 848);
  CHECK(cv::norm(fa.images[0], fb.images[0], cv::NORM_INF) == 0);
  CHECK(cv::norm(fa.images[3], fb.images[3], cv::NORM_INF) == 0);
  Frame f2;
  REQUIRE(a.grab(f2));  // the next frame's noise differs
  CHECK(cv::norm(fa.images[0], f2.images[0], cv::NORM_INF) > 0);
}
