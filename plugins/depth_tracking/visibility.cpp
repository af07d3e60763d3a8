#include "plugins/depth_tracking/visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/errors.h"

namespace crease::depth {
namespace {

void check(bool ok, const char* key, const std::string& reason) {
  if (!ok) throw ConfigError(std::string("depth_tracking: ") + key + ": " + reason);
}

constexpr float kInf = std::numeric_limits<float>::infinity();
// Half-width, in full-resolution pixels, of the window the depth check reads around a node's
// pixel: the node is hidden only if no pixel of it sees as far as the node (a node at the edge of
// an occluder stays seen; the 1 mm depth noise and holes do not hide one).
constexpr int kDepthWindow = 2;

}  // namespace

void NodeVisibility::configure(const std::vector<vision::Camera>& cameras, int nodes_u, int nodes_v,
                               int scale, int cells) {
  check(!cameras.empty() && cameras.size() <= 32, "cameras", "1 to 32 depth cameras");
  check(nodes_u >= 2 && nodes_v >= 2, "nodes", "a grid of at least 2 x 2");
  check(scale >= 1 && scale <= 64, "visibility_scale", "must be in [1, 64]");
  check(cells >= 0 && cells <= 64, "visibility_cells", "must be in [0, 64]");
  nu_ = nodes_u;
  nv_ = nodes_v;
  cells_ = cells;
  scale_ = scale;
  unit_mm_.assign(cameras.size(), 1.0);
  occluder_mm_ = 0.0;
  views_.clear();
  for (const vision::Camera& c : cameras) {
    View v;
    v.cam = c;
    const double s = 1.0 / scale;
    v.cam.K(0, 0) *= s;
    v.cam.K(1, 1) *= s;
    v.cam.K(0, 1) *= s;
    v.cam.K(0, 2) = (c.K(0, 2) + 0.5) * s - 0.5;
    v.cam.K(1, 2) = (c.K(1, 2) + 0.5) * s - 0.5;
    v.w = std::max(1, c.width / scale);
    v.h = std::max(1, c.height / scale);
    v.cam.width = v.w;
    v.cam.height = v.h;
    v.zbuf.assign(static_cast<std::size_t>(v.w) * static_cast<std::size_t>(v.h), kInf);
    v.cell.assign(v.zbuf.size(), -1);
    views_.push_back(std::move(v));
  }
  proj_.assign(static_cast<std::size_t>(nu_) * static_cast<std::size_t>(nv_), Eigen::Vector3d::Zero());
}

void NodeVisibility::set_depth_check(const std::vector<double>& depth_unit_mm, double occluder_mm) {
  check(depth_unit_mm.size() == views_.size(), "cameras", "one depth unit per camera");
  check(occluder_mm >= 0.0 && std::isfinite(occluder_mm), "occluder_mm", "must be finite and >= 0");
  for (const double u : depth_unit_mm)
    check(u > 0.0 && std::isfinite(u), "depth_unit_mm", "must be > 0");
  unit_mm_ = depth_unit_mm;
  occluder_mm_ = occluder_mm;
}

bool NodeVisibility::set_pose(std::size_t k, const cv::Matx33d& R, const cv::Vec3d& t) noexcept {
  if (k >= views_.size()) return false;
  views_[k].cam.R = R;  // the scaled intrinsics are the view's own: only the pose moves
  views_[k].cam.t = t;
  return true;
}

double NodeVisibility::farthest_depth_mm(const cv::Mat& depth, double unit_mm, double x,
                                         double y) const noexcept {
  const int cx = static_cast<int>(std::lround(x)), cy = static_cast<int>(std::lround(y));
  std::uint16_t far = 0;
  for (int yy = std::max(0, cy - kDepthWindow); yy <= std::min(depth.rows - 1, cy + kDepthWindow);
       ++yy) {
    const auto* row = depth.ptr<std::uint16_t>(yy);
    for (int xx = std::max(0, cx - kDepthWindow); xx <= std::min(depth.cols - 1, cx + kDepthWindow);
         ++xx)
      far = std::max(far, row[xx]);
  }
  return far * unit_mm;
}

bool NodeVisibility::compute(std::span<const Eigen::Vector3d> nodes, std::uint32_t mask,
                             std::span<std::uint32_t> seen,
                             std::span<const cv::Mat> depth) noexcept {
  const std::size_t n = proj_.size();
  if (nodes.size() != n || seen.size() != n) return false;
  std::fill(seen.begin(), seen.end(), 0u);
  occluded_ = 0;
  for (std::size_t k = 0; k < views_.size(); ++k) {
    if (((mask >> k) & 1u) == 0) continue;
    View& v = views_[k];
    std::fill(v.zbuf.begin(), v.zbuf.end(), kInf);
    std::fill(v.cell.begin(), v.cell.end(), -1);
    for (std::size_t i = 0; i < n; ++i) {
      const cv::Vec3d w(nodes[i][0], nodes[i][1], nodes[i][2]);
      const cv::Vec3d pc = v.cam.to_camera(w);
      cv::Point2d px;
      if (pc[2] <= 1.0 || !v.cam.project(w, px)) {
        proj_[i] = Eigen::Vector3d(0, 0, -1);
        continue;
      }
      proj_[i] = Eigen::Vector3d(px.x, px.y, pc[2]);
    }
    // Rasterise both triangles of every grid cell (z linear in the image: cells are small).
    const auto raster = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                            std::int32_t cell) {
      if (a[2] <= 0 || b[2] <= 0 || c[2] <= 0) return;
      const double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
      if (std::abs(area) < 1e-9) return;
      const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a[0], b[0], c[0]}))));
      const int x1 = std::min(v.w - 1, static_cast<int>(std::floor(std::max({a[0], b[0], c[0]}))));
      const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a[1], b[1], c[1]}))));
      const int y1 = std::min(v.h - 1, static_cast<int>(std::floor(std::max({a[1], b[1], c[1]}))));
      const double inv = 1.0 / area;
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const double wa = ((b[0] - x) * (c[1] - y) - (b[1] - y) * (c[0] - x)) * inv;
          const double wb = ((c[0] - x) * (a[1] - y) - (c[1] - y) * (a[0] - x)) * inv;
          const double wc = 1.0 - wa - wb;
          if (wa < -1e-9 || wb < -1e-9 || wc < -1e-9) continue;
          const float z = static_cast<float>(wa * a[2] + wb * b[2] + wc * c[2]);
          const std::size_t px = static_cast<std::size_t>(y) * static_cast<std::size_t>(v.w) + static_cast<std::size_t>(x);
          if (z < v.zbuf[px]) {
            v.zbuf[px] = z;
            v.cell[px] = cell;
          }
        }
    };
    for (int j = 0; j + 1 < nv_; ++j)
      for (int i = 0; i + 1 < nu_; ++i) {
        const std::size_t p00 = static_cast<std::size_t>(j * nu_ + i), p10 = p00 + 1;
        const std::size_t p01 = p00 + static_cast<std::size_t>(nu_), p11 = p01 + 1;
        const std::int32_t cell = j * (nu_ - 1) + i;
        raster(proj_[p00], proj_[p10], proj_[p01], cell);
        raster(proj_[p10], proj_[p11], proj_[p01], cell);
      }
    const cv::Mat* dimg = nullptr;
    if (occluder_mm_ > 0.0 && k < depth.size() && !depth[k].empty() && depth[k].type() == CV_16UC1)
      dimg = &depth[k];
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d& p = proj_[i];
      if (p[2] <= 0) continue;
      const int x = static_cast<int>(std::lround(p[0])), y = static_cast<int>(std::lround(p[1]));
      if (x < 0 || y < 0 || x >= v.w || y >= v.h) continue;
      const int ni = static_cast<int>(i) % nu_, nj = static_cast<int>(i) / nu_;
      bool own = false;
      for (int dy = -1; dy <= 1 && !own; ++dy)
        for (int dx = -1; dx <= 1 && !own; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= v.w || yy >= v.h) continue;
          const std::int32_t c = v.cell[static_cast<std::size_t>(yy) * static_cast<std::size_t>(v.w) + static_cast<std::size_t>(xx)];
          if (c < 0) continue;
          const int ci = c % (nu_ - 1), cj = c / (nu_ - 1);
          // The node's own cells are (ni-1..ni, nj-1..nj): grid distance to the nearest of them.
          const int di = ci < ni - 1 ? ni - 1 - ci : (ci > ni ? ci - ni : 0);
          const int dj = cj < nj - 1 ? nj - 1 - cj : (cj > nj ? cj - nj : 0);
          own = std::max(di, dj) <= cells_;
        }
      if (!own) continue;
      if (dimg != nullptr) {
        // The scaled pixel back at full resolution (the inverse of configure's scaling of K).
        const double far = farthest_depth_mm(*dimg, unit_mm_[k], (p[0] + 0.5) * scale_ - 0.5,
                                             (p[1] + 0.5) * scale_ - 0.5);
        if (far > 0.0 && far < p[2] - occluder_mm_) {
          ++occluded_;
          continue;
        }
      }
      seen[i] |= 1u << k;
    }
  }
  return true;
}

}  // namespace crease::depth
