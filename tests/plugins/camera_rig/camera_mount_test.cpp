// A camera the robot carries (plugins/camera_rig/camera_mount.h): the shipped wrist calibrations
// (config/wrist_cameras) name their mount; bad mount keys are configuration errors naming the
// file and the key; a file without them is a camera fixed in the world; the pose composed with
// the mount shape's puts the camera where the shape carries it.
#include "plugins/camera_rig/camera_mount.h"

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.h"
#include "plugins/camera_rig/depth_camera.h"

using namespace crease::vision;

namespace {
const std::string kSrc = CREASE_SOURCE_DIR;

// The shipped right wrist camera's file with its mount keys replaced by EXTRA.
std::string with_mount(const std::string& name, const std::string& extra) {
  std::ifstream in(kSrc + "/config/wrist_cameras/cam0.yaml");
  std::string text, line;
  while (std::getline(in, line))
    if (line.rfind("mount_", 0) != 0) text += line + "\n";
  const std::string path =
      (std::filesystem::temp_directory_path() / ("crease_mount_" + name + ".yaml")).string();
  std::ofstream(path) << text << extra;
  return path;
}

std::string error_of(const std::string& path) {
  try {
    (void)load_depth_camera(path);
  } catch (const crease::ConfigError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST_CASE("the shipped wrist cameras: D405-like, carried on each forearm's capsule") {
  const auto cams = load_depth_camera_dir(kSrc + "/config/wrist_cameras");
  REQUIRE(cams.size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    CAPTURE(k);
    CHECK(cams[k].camera.width == 848);
    CHECK(cams[k].camera.height == 480);
    CHECK(cams[k].depth_unit_mm == 0.1);
    REQUIRE(cams[k].mount.has_value());
    CHECK(cams[k].mount->side == k);
    CHECK(cams[k].mount->role == crease::WorldShapes::Role::hand);
    CHECK(cams[k].mount->index == 1);
    // 70 mm off the forearm's axis on the palm's side: outside the capsule (radius 45 mm).
    const cv::Vec3d c = cams[k].camera.centre_world();  // in the shape's frame
    CHECK(std::hypot(c[0], c[1]) == doctest::Approx(70.0));
  }
  CHECK(describe(*cams[1].mount) == "left hand #1");
  // The fixed D435s have no mount.
  for (const auto& c : load_depth_camera_dir(kSrc + "/config/depth_cameras"))
    CHECK(!c.mount.has_value());
}

TEST_CASE("bad mount keys: a configuration error naming the file and the key") {
  struct Case {
    const char* name;
    const char* keys;
    const char* key;
    const char* why;
  };
  const Case cases[] = {
      {"side", "mount_side: middle\nmount_role: hand\n", "mount_side", "'middle' is no side"},
      {"side_number", "mount_side: 2\nmount_role: hand\n", "mount_side", "expected a name"},
      {"role", "mount_side: right\nmount_role: elbow\n", "mount_role", "'elbow' is no shape role"},
      {"no_role", "mount_side: left\n", "mount_role", "missing"},
      {"index", "mount_side: left\nmount_role: palm\nmount_index: -1\n", "mount_index",
       "must be in [0, 128)"},
      {"index_text", "mount_side: left\nmount_role: palm\nmount_index: one\n", "mount_index",
       "expected an integer"},
      {"role_alone", "mount_role: palm\n", "mount_role", "given without mount_side"},
  };
  for (const Case& c : cases) {
    CAPTURE(std::string(c.name));
    const std::string path = with_mount(c.name, c.keys);
    const std::string what = error_of(path);
    CAPTURE(what);
    CHECK(what.find(path + ": key '" + c.key + "': " + c.why) == 0);
    std::filesystem::remove(path);
  }
}

TEST_CASE("a mount saved with its calibration reads back; none reads back as a fixed camera") {
  DepthCamera cam = load_depth_camera_dir(kSrc + "/config/wrist_cameras")[1];
  cam.mount = CameraMount{1, crease::WorldShapes::Role::palm, 0};
  const std::string path =
      (std::filesystem::temp_directory_path() / "crease_mount_saved.yaml").string();
  save_depth_camera(cam, path);
  const DepthCamera back = load_depth_camera(path);
  REQUIRE(back.mount.has_value());
  CHECK(back.mount->side == 1);
  CHECK(back.mount->role == crease::WorldShapes::Role::palm);
  CHECK(back.mount->index == 0);
  CHECK(back.depth_unit_mm == 0.1);
  cam.mount.reset();
  save_depth_camera(cam, path);
  CHECK(!load_depth_camera(path).mount.has_value());
  std::filesystem::remove(path);
}

TEST_CASE("place_on_mount: the camera goes where its shape carries it") {
  // The mount: the camera 50 mm along the shape's x, looking along the shape's x (camera z = x).
  const cv::Matx33d mount_R(0, 1, 0, 0, 0, 1, 1, 0, 0);
  const cv::Vec3d centre_in_shape(50, 0, 0);
  const cv::Vec3d mount_t = -(mount_R * centre_in_shape);
  // The shape at (100, 200, 300), turned 90 deg about the world z: its x is the world's y.
  const cv::Matx33d shape_R(0, -1, 0, 1, 0, 0, 0, 0, 1);
  const cv::Vec3d shape_p(100, 200, 300);
  cv::Matx33d R;
  cv::Vec3d t;
  place_on_mount(mount_R, mount_t, shape_R, shape_p, R, t);
  Camera cam;
  cam.R = R;
  cam.t = t;
  const cv::Vec3d c = cam.centre_world();
  CHECK(c[0] == doctest::Approx(100.0));
  CHECK(c[1] == doctest::Approx(250.0));
  CHECK(c[2] == doctest::Approx(300.0));
  // Its optical axis is the shape's x, the world's y: a point ahead of it is at camera (0, 0, d).
  const cv::Vec3d ahead = cam.to_camera({100, 400, 300});
  CHECK(ahead[0] == doctest::Approx(0.0));
  CHECK(ahead[1] == doctest::Approx(0.0));
  CHECK(ahead[2] == doctest::Approx(150.0));
  CHECK(cv::determinant(R) == doctest::Approx(1.0));
}
