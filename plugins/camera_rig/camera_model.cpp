#include "plugins/camera_rig/camera_model.h"

#include <cmath>
#include <filesystem>

#include <opencv2/core/persistence.hpp>

#include "core/assert.h"

namespace crease::vision {

cv::Point2d Camera::distort(const cv::Point2d& n) const {
  const double x = n.x, y = n.y;
  const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const auto& d = dist;
  const double radial = (1 + d[0] * r2 + d[1] * r4 + d[4] * r6) / (1 + d[5] * r2 + d[6] * r4 + d[7] * r6);
  const double xd = x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x);
  const double yd = y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y;
  return {K(0, 0) * xd + K(0, 1) * yd + K(0, 2), K(1, 1) * yd + K(1, 2)};
}

bool Camera::project(const cv::Vec3d& w, cv::Point2d& px) const {
  const cv::Vec3d c = to_camera(w);
  if (c[2] <= 1e-9) return false;
  px = distort({c[0] / c[2], c[1] / c[2]});
  return true;
}

cv::Point2d Camera::undistort(const cv::Point2d& px) const {
  // Invert K, then iterate x = (xd - tangential(x)) / radial(x) (as cv::undistortPoints),
  // finished by Newton-free fixed point refinement; converges for moderate distortion.
  const double yd = (px.y - K(1, 2)) / K(1, 1);
  const double xd = (px.x - K(0, 2) - K(0, 1) * yd) / K(0, 0);
  double x = xd, y = yd;
  const auto& d = dist;
  for (int it = 0; it < 20; ++it) {
    const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
    const double icdist = (1 + d[5] * r2 + d[6] * r4 + d[7] * r6) / (1 + d[0] * r2 + d[1] * r4 + d[4] * r6);
    const double dx = 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x);
    const double dy = d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y;
    const double nx = (xd - dx) * icdist, ny = (yd - dy) * icdist;
    const double step = std::abs(nx - x) + std::abs(ny - y);
    x = nx;
    y = ny;
    if (step < 1e-12) break;
  }
  return {x, y};
}

cv::Mat Camera::dist_mat() const {
  cv::Mat m(1, dist_count, CV_64F);
  for (int i = 0; i < dist_count; ++i) m.at<double>(0, i) = dist[static_cast<std::size_t>(i)];
  return m;
}

Camera look_at_camera(const std::string& name, int width, int height, double f,
                      const cv::Vec3d& eye, const cv::Vec3d& target) {
  Camera c;
  c.name = name;
  c.width = width;
  c.height = height;
  c.K = cv::Matx33d(f, 0, (width - 1) / 2.0, 0, f, (height - 1) / 2.0, 0, 0, 1);
  const cv::Vec3d z = cv::normalize(target - eye);  // optical axis
  cv::Vec3d up(0, 0, 1);
  if (std::abs(z.dot(up)) > 0.99) up = cv::Vec3d(0, 1, 0);
  const cv::Vec3d x = cv::normalize(z.cross(up));  // image right
  const cv::Vec3d y = z.cross(x);                  // image down
  c.R = cv::Matx33d(x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]);
  c.t = -(c.R * eye);
  return c;
}

std::vector<Camera> default_rig() {
  std::vector<Camera> rig;
  const cv::Vec3d target(0, 0, 0);
  rig.push_back(look_at_camera("cam0", 1280, 960, 1400, {0, -50, 600}, target));
  const double r = 400, z = 450;
  const cv::Vec3d eyes[4] = {{r, r, z}, {-r, r, z}, {-r, -r, z}, {r, -r, z}};
  for (int k = 0; k < 4; ++k)
    rig.push_back(look_at_camera("cam" + std::to_string(k + 1), 1280, 960, 1400 + 40 * k, eyes[k], target));
  const double d[5][5] = {{-0.08, 0.06, 0.0005, -0.0003, 0},
                          {-0.06, 0.03, -0.0002, 0.0004, 0},
                          {-0.10, 0.09, 0.0003, 0.0002, -0.02},
                          {-0.07, 0.05, 0, 0, 0},
                          {-0.09, 0.07, -0.0004, -0.0001, 0}};
  for (int k = 0; k < 5; ++k) {
    for (int i = 0; i < 5; ++i) rig[static_cast<std::size_t>(k)].dist[static_cast<std::size_t>(i)] = d[k][i];
    rig[static_cast<std::size_t>(k)].K(0, 2) += 3.5 * (k - 2);
    rig[static_cast<std::size_t>(k)].K(1, 2) -= 2.0 * (k - 2);
  }
  return rig;
}

namespace {

// cv::FileStorage keeps no line numbers: the file and the key.
[[noreturn]] void fail(const std::string& path, const std::string& key, const std::string& why) {
  throw crease::ConfigError(path + ": key '" + key + "': " + why);
}

cv::Mat read_matrix(const cv::FileStorage& fs, const std::string& path, const char* key, int rows,
                    int cols) {
  const cv::FileNode n = fs[key];
  if (n.empty()) fail(path, key, "missing");
  cv::Mat m;
  try {
    n >> m;
  } catch (const cv::Exception&) {
    fail(path, key, "not a matrix");
  }
  if (m.empty()) fail(path, key, "not a matrix");
  if (m.rows != rows || m.cols != cols)
    fail(path, key, "expected " + std::to_string(rows) + "x" + std::to_string(cols) + ", got " +
                        std::to_string(m.rows) + "x" + std::to_string(m.cols));
  m.convertTo(m, CV_64F);
  for (auto it = m.begin<double>(); it != m.end<double>(); ++it)
    if (!std::isfinite(*it)) fail(path, key, "non-finite entry");
  return m;
}

int read_int(const cv::FileStorage& fs, const std::string& path, const char* key) {
  const cv::FileNode n = fs[key];
  if (n.empty()) fail(path, key, "missing");
  if (!n.isInt()) fail(path, key, "expected an integer");
  const int v = static_cast<int>(n);
  if (v <= 0) fail(path, key, "must be positive");
  return v;
}

}  // namespace

Camera load_camera(const std::string& path) {
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ)) throw crease::ConfigError(path + ": cannot read calibration file");
  } catch (const cv::Exception& e) {
    throw crease::ConfigError(path + ": cannot parse calibration file: " + e.err);
  }
  Camera c;
  c.name = std::filesystem::path(path).stem().string();
  c.width = read_int(fs, path, "image_width");
  c.height = read_int(fs, path, "image_height");
  const cv::Mat K = read_matrix(fs, path, "camera_matrix", 3, 3);
  c.K = cv::Matx33d(K.ptr<double>());
  if (!(c.K(0, 0) > 0) || !(c.K(1, 1) > 0)) fail(path, "camera_matrix", "non-positive focal length");
  if (c.K(1, 0) != 0 || c.K(2, 0) != 0 || c.K(2, 1) != 0 || c.K(2, 2) != 1)
    fail(path, "camera_matrix", "last row must be [0 0 1] and K(1,0) zero");
  const cv::FileNode dn = fs["distortion_coefficients"];
  if (dn.empty()) fail(path, "distortion_coefficients", "missing");
  cv::Mat d;
  dn >> d;
  const int nd = static_cast<int>(d.total());
  if (d.empty() || (d.rows != 1 && d.cols != 1) || (nd != 4 && nd != 5 && nd != 8))
    fail(path, "distortion_coefficients", "expected 4, 5 or 8 coefficients in one row or column");
  d.convertTo(d, CV_64F);
  c.dist_count = nd;
  for (int i = 0; i < nd; ++i) c.dist[static_cast<std::size_t>(i)] = d.at<double>(i);
  const cv::Mat R = read_matrix(fs, path, "rotation", 3, 3);
  c.R = cv::Matx33d(R.ptr<double>());
  const cv::Matx33d e = c.R * c.R.t() - cv::Matx33d::eye();
  if (cv::norm(e) > 1e-6 || cv::determinant(c.R) < 0) fail(path, "rotation", "not a rotation matrix");
  cv::Mat t = read_matrix(fs, path, "translation", 3, 1);
  c.t = cv::Vec3d(t.ptr<double>());
  return c;
}

void save_camera(const Camera& c, const std::string& path) {
  cv::FileStorage fs;
  if (!fs.open(path, cv::FileStorage::WRITE)) throw crease::Error(path + ": cannot open for writing");
  fs.writeComment("Crease camera calibration: pinhole + OpenCV distortion; pose maps world to camera "
                  "(x_cam = rotation * x_world + translation), millimetres.");
  fs << "image_width" << c.width << "image_height" << c.height;
  fs << "camera_matrix" << cv::Mat(c.K);
  fs << "distortion_coefficients" << c.dist_mat();
  fs << "rotation" << cv::Mat(c.R);
  fs << "translation" << cv::Mat(c.t);
}

std::vector<Camera> load_camera_dir(const std::string& dir) {
  std::vector<Camera> cams;
  for (int k = 0;; ++k) {
    const std::string p = dir + "/cam" + std::to_string(k) + ".yaml";
    if (!std::filesystem::exists(p)) break;
    cams.push_back(load_camera(p));
  }
  crease::require_input(!cams.empty(), dir + ": no camera files cam0.yaml, cam1.yaml, ...");
  return cams;
}

}  // namespace crease::vision
