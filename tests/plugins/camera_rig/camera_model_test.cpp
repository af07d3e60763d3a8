#include "plugins/camera_rig/camera_model.h"

#include <filesystem>
#include <fstream>
#include <string>

#include <doctest/doctest.h>

using namespace crease::vision;

namespace {
std::string tmp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("crease_vision_cam_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

// A valid file with one line replaced (or removed when `with` is empty).
std::string variant(const std::string& key, const std::string& with) {
  const Camera c = default_rig()[1];
  const std::string good = tmp_path("good.yaml");
  save_camera(c, good);
  std::ifstream in(good);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const auto a = text.find(key + ":");
  REQUIRE(a != std::string::npos);
  auto b = text.find('\n', a);
  // A matrix node spans until the next top-level key (a line not starting with a space).
  while (b + 1 < text.size() && text[b + 1] == ' ') b = text.find('\n', b + 1);
  text.replace(a, b - a + 1, with);
  const std::string p = tmp_path("bad_" + key + ".yaml");
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST_CASE("projection and undistortion are inverse; pose helpers agree") {
  for (const Camera& c : default_rig()) {
    CHECK(cv::norm(c.centre_world() - (-(c.R.t() * c.t))) < 1e-9);
    for (double x = -100; x <= 100; x += 50)
      for (double y = -140; y <= 140; y += 70) {
        cv::Point2d px;
        REQUIRE(c.project({x, y, 5}, px));
        CHECK(px.x > 0);
        CHECK(px.x < c.width);
        const cv::Vec3d pc = c.to_camera({x, y, 5});
        const cv::Point2d n = c.undistort(px);
        CHECK(std::abs(n.x - pc[0] / pc[2]) < 1e-9);
        CHECK(std::abs(n.y - pc[1] / pc[2]) < 1e-9);
      }
  }
}

TEST_CASE("calibration files round-trip") {
  for (const Camera& c : default_rig()) {
    const std::string p = tmp_path(c.name + ".yaml");
    save_camera(c, p);
    const Camera r = load_camera(p);
    CHECK(r.width == c.width);
    CHECK(r.height == c.height);
    CHECK(cv::norm(cv::Mat(r.K), cv::Mat(c.K)) < 1e-9);
    CHECK(cv::norm(cv::Mat(r.R), cv::Mat(c.R)) < 1e-12);
    CHECK(cv::norm(r.t - c.t) < 1e-9);
    for (int i = 0; i < 8; ++i) CHECK(r.dist[static_cast<std::size_t>(i)] == c.dist[static_cast<std::size_t>(i)]);
  }
}

TEST_CASE("bad calibration files name the file and the key") {
  auto expect = [](const std::string& path, const std::string& key, const std::string& why) {
    try {
      (void)load_camera(path);
      FAIL("no exception for " << path);
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      CHECK_MESSAGE(m.find(path) != std::string::npos, m);
      CHECK_MESSAGE(m.find("'" + key + "'") != std::string::npos, m);
      CHECK_MESSAGE(m.find(why) != std::string::npos, m);
    }
  };
  expect(variant("image_width", ""), "image_width", "missing");
  expect(variant("translation", ""), "translation", "missing");
  expect(variant("camera_matrix",
                 "camera_matrix: !!opencv-matrix\n   rows: 2\n   cols: 2\n   dt: d\n   data: [ 1., 0., 0., 1. ]\n"),
         "camera_matrix", "expected 3x3");
  expect(variant("camera_matrix",
                 "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                 "   data: [ -100., 0., 640., 0., 100., 480., 0., 0., 1. ]\n"),
         "camera_matrix", "non-positive focal length");
  expect(variant("rotation",
                 "rotation: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                 "   data: [ 2., 0., 0., 0., 1., 0., 0., 0., 1. ]\n"),
         "rotation", "not a rotation");
  expect(variant("distortion_coefficients",
                 "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 3\n   dt: d\n   data: [ 0., 0., 0. ]\n"),
         "distortion_coefficients", "coefficients");
  const std::string missing = tmp_path("does_not_exist.yaml");
  CHECK_THROWS_WITH_AS(load_camera(missing), doctest::Contains("does_not_exist.yaml"), std::runtime_error);
  const std::string garbage = tmp_path("garbage.yaml");
  std::ofstream(garbage) << "%YAML:1.0\n---\ncamera_matrix: [1, 2\n";
  CHECK_THROWS_WITH_AS(load_camera(garbage), doctest::Contains("garbage.yaml"), std::runtime_error);
}

TEST_CASE("the shipped rig in config/cameras loads") {
  const auto cams = load_camera_dir(std::string(CREASE_SOURCE_DIR) + "/config/cameras");
  CHECK(cams.size() == 5);
  for (const auto& c : cams) {
    CHECK(c.width == 1280);
    CHECK(c.height == 960);
  }
}
