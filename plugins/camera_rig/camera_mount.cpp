#include "plugins/camera_rig/camera_mount.h"

#include <array>
#include <cmath>
#include <opencv2/core/persistence.hpp>
#include <string_view>

#include "core/errors.h"

namespace crease::vision {

namespace {

using Role = crease::WorldShapes::Role;

constexpr std::array<std::string_view, 2> kSides = {"right", "left"};
// WorldShapes::Role by value.
constexpr std::array<std::string_view, 7> kRoles = {"pad",  "back", "fingertip", "finger",
                                                    "palm", "hand", "arm"};

[[noreturn]] void fail(const std::string& path, const char* key, const std::string& why) {
  throw crease::ConfigError(path + ": key '" + key + "': " + why);
}

std::string read_name(const cv::FileNode& n, const std::string& path, const char* key) {
  if (!n.isString()) fail(path, key, "expected a name");
  return static_cast<std::string>(n);
}

template <std::size_t N>
std::string choices(const std::array<std::string_view, N>& names) {
  std::string s;
  for (std::string_view v : names) s += (s.empty() ? "" : " | ") + std::string(v);
  return s;
}

template <std::size_t N>
int find_name(const std::array<std::string_view, N>& names, const std::string& name) {
  for (std::size_t i = 0; i < N; ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

}  // namespace

std::optional<CameraMount> load_camera_mount(const std::string& path) {
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ))
      throw crease::ConfigError(path + ": cannot read calibration file");
  } catch (const cv::Exception& e) {
    throw crease::ConfigError(path + ": cannot parse calibration file: " + e.err);
  }
  const cv::FileNode side = fs["mount_side"], role = fs["mount_role"], index = fs["mount_index"];
  if (side.empty()) {
    if (!role.empty())
      fail(path, "mount_role",
           "given without mount_side (a camera fixed in the world has neither)");
    if (!index.empty())
      fail(path, "mount_index",
           "given without mount_side (a camera fixed in the world has neither)");
    return std::nullopt;
  }
  CameraMount m;
  const std::string s = read_name(side, path, "mount_side");
  const int si = find_name(kSides, s);
  if (si < 0) fail(path, "mount_side", "'" + s + "' is no side: " + choices(kSides));
  m.side = static_cast<std::uint8_t>(si);
  if (role.empty())
    fail(path, "mount_role", "missing (the shape of that side the camera is mounted on)");
  const std::string r = read_name(role, path, "mount_role");
  const int ri = find_name(kRoles, r);
  if (ri < 0) fail(path, "mount_role", "'" + r + "' is no shape role: " + choices(kRoles));
  m.role = static_cast<Role>(ri);
  if (!index.empty()) {
    if (!index.isInt()) fail(path, "mount_index", "expected an integer");
    m.index = static_cast<int>(index);
    if (m.index < 0 || m.index >= static_cast<int>(crease::WorldShapes::kCapacity))
      fail(path, "mount_index",
           "must be in [0, " + std::to_string(crease::WorldShapes::kCapacity) + ")");
  }
  return m;
}

void save_camera_mount(const CameraMount& m, const std::string& path) {
  cv::FileStorage fs(path, cv::FileStorage::APPEND);
  if (!fs.isOpened()) throw crease::Error(path + ": cannot open for writing");
  fs << "mount_side" << std::string(kSides.at(m.side));
  fs << "mount_role" << std::string(kRoles.at(static_cast<std::size_t>(m.role)));
  fs << "mount_index" << m.index;
}

std::string describe(const CameraMount& m) {
  return std::string(kSides.at(m.side)) + " " +
         std::string(kRoles.at(static_cast<std::size_t>(m.role))) + " #" + std::to_string(m.index);
}

void place_on_mount(const cv::Matx33d& mount_R, const cv::Vec3d& mount_t,
                    const cv::Matx33d& shape_R, const cv::Vec3d& shape_p, cv::Matx33d& R,
                    cv::Vec3d& t) noexcept {
  // x_cam = mount_R * shape_R^T * (x_world - shape_p) + mount_t.
  R = mount_R * shape_R.t();
  t = mount_t - R * shape_p;
}

crease::frames::CameraPose carried_pose(const cv::Matx33d& R, const cv::Vec3d& t) noexcept {
  // x_world = R^T (x_cam - t): world-from-camera rotation R^T, the camera's centre -R^T t.
  crease::frames::CameraPose p;
  p.carried = true;
  const cv::Matx33d Rt = R.t();
  const cv::Vec3d c = -(Rt * t);
  for (int k = 0; k < 9; ++k) p.rotation[k] = Rt.val[k];
  for (int k = 0; k < 3; ++k) p.translation_mm[k] = c[k];
  return p;
}

bool camera_from_pose(const crease::frames::CameraPose& pose, cv::Matx33d& R,
                      cv::Vec3d& t) noexcept {
  cv::Matx33d wc;  // world-from-camera
  cv::Vec3d c;
  for (int k = 0; k < 9; ++k) {
    if (!std::isfinite(pose.rotation[k])) return false;
    wc.val[k] = pose.rotation[k];
  }
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(pose.translation_mm[k])) return false;
    c[k] = pose.translation_mm[k];
  }
  const cv::Matx33d g = wc.t() * wc;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (std::abs(g(i, j) - (i == j ? 1.0 : 0.0)) > 1e-6) return false;
  if (cv::determinant(wc) < 0) return false;
  R = wc.t();
  t = -(R * c);
  return true;
}

}  // namespace crease::vision
