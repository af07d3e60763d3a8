#include "plugins/vision/triangulation.h"

#include <cmath>

#include <Eigen/Dense>

namespace crease::vision {

namespace {

// Reprojection error in pixels (normalized error scaled by the focal length).
double reproj_px(const Camera& c, const ViewObservation& o, const cv::Vec3d& X) {
  const cv::Vec3d p = c.to_camera(X);
  if (p[2] <= 1e-9) return 1e12;
  const double ex = p[0] / p[2] - o.normalized.x, ey = p[1] / p[2] - o.normalized.y;
  return std::sqrt(ex * ex * c.K(0, 0) * c.K(0, 0) + ey * ey * c.K(1, 1) * c.K(1, 1));
}

bool dlt_subset(const Camera* cams, const ViewObservation* obs, int n, std::uint32_t mask, cv::Vec3d& X) {
  Eigen::Matrix4d AtA = Eigen::Matrix4d::Zero();
  int used = 0;
  for (int i = 0; i < n; ++i) {
    if (!(mask & (1u << i))) continue;
    const Camera& c = cams[obs[i].camera];
    Eigen::Matrix<double, 3, 4> P;
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) P(r, k) = c.R(r, k);
      P(r, 3) = c.t[r];
    }
    for (int row = 0; row < 2; ++row) {
      const double m = row == 0 ? obs[i].normalized.x : obs[i].normalized.y;
      Eigen::Matrix<double, 1, 4> a = m * P.row(2) - P.row(row);
      const double nrm = a.norm();
      if (nrm > 0) a /= nrm;
      AtA += a.transpose() * a;
    }
    ++used;
  }
  if (used < 2) return false;
  // The point minimising |A (X, 1)|: the 3x3 normal equations with the homogeneous coordinate
  // fixed at 1 (points at a finite distance). About 6 times cheaper than the 4x4 eigenvector,
  // and the same point up to noise; the Gauss-Newton refinement after it sets the final one.
  const Eigen::Matrix3d M = AtA.topLeftCorner<3, 3>();
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(M);
  if (ldlt.info() != Eigen::Success || ldlt.rcond() < 1e-12) return false;
  const Eigen::Vector3d h = ldlt.solve(-AtA.topRightCorner<3, 1>());
  X = cv::Vec3d(h[0], h[1], h[2]);
  for (int i = 0; i < n; ++i)
    if ((mask & (1u << i)) && cams[obs[i].camera].to_camera(X)[2] <= 0) return false;
  return std::isfinite(X[0]) && std::isfinite(X[1]) && std::isfinite(X[2]);
}

// Gauss-Newton on the pixel-scaled normalized reprojection error of the masked views.
void gauss_newton(const Camera* cams, const ViewObservation* obs, int n, std::uint32_t mask, cv::Vec3d& X) {
  for (int it = 0; it < 5; ++it) {
    Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      if (!(mask & (1u << i))) continue;
      const Camera& c = cams[obs[i].camera];
      const cv::Vec3d p = c.to_camera(X);
      if (p[2] <= 1e-9) return;
      const double iz = 1.0 / p[2];
      const double fx = c.K(0, 0), fy = c.K(1, 1);
      const Eigen::Vector2d r(fx * (p[0] * iz - obs[i].normalized.x), fy * (p[1] * iz - obs[i].normalized.y));
      Eigen::Matrix<double, 2, 3> dp;  // d(normalized)/d(camera point), scaled to pixels
      dp << fx * iz, 0, -fx * p[0] * iz * iz, 0, fy * iz, -fy * p[1] * iz * iz;
      Eigen::Matrix3d R;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) R(a, b) = c.R(a, b);
      const Eigen::Matrix<double, 2, 3> J = dp * R;
      JtJ += J.transpose() * J;
      Jtr += J.transpose() * r;
    }
    const Eigen::Vector3d dx = JtJ.ldlt().solve(-Jtr);
    if (!dx.allFinite()) return;
    X += cv::Vec3d(dx[0], dx[1], dx[2]);
    if (dx.norm() < 1e-6) return;
  }
}

}  // namespace

bool triangulate_dlt(const Camera* cams, const ViewObservation* obs, int n, cv::Vec3d& X) {
  if (n < 2 || n > kMaxViews) return false;
  return dlt_subset(cams, obs, n, (1u << n) - 1u, X);
}

bool triangulate(const Camera* cams, const ViewObservation* obs, int n, const TriangulationConfig& cfg,
                 TriangulatedPoint& out) {
  if (n < std::max(2, cfg.min_views) || n > kMaxViews) return false;
  const std::uint32_t all = (1u << n) - 1u;
  auto inliers_of = [&](const cv::Vec3d& X) {
    std::uint32_t m = 0;
    for (int i = 0; i < n; ++i)
      if (reproj_px(cams[obs[i].camera], obs[i], X) <= cfg.max_reproj_px) m |= 1u << i;
    return m;
  };
  // Try all views first; if one disagrees, seed from every pair and keep the largest consensus.
  cv::Vec3d X;
  std::uint32_t best = 0;
  if (dlt_subset(cams, obs, n, all, X)) best = inliers_of(X);
  if (best != all) {
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b) {
        cv::Vec3d Y;
        if (!dlt_subset(cams, obs, n, (1u << a) | (1u << b), Y)) continue;
        const std::uint32_t m = inliers_of(Y);
        if (__builtin_popcount(m) > __builtin_popcount(best)) best = m;
      }
  }
  if (__builtin_popcount(best) < std::max(2, cfg.min_views)) return false;
  if (!dlt_subset(cams, obs, n, best, X)) return false;
  if (cfg.refine) gauss_newton(cams, obs, n, best, X);
  // Final inlier set and error on the refined point.
  const std::uint32_t fin = inliers_of(X) & best;
  if (__builtin_popcount(fin) < std::max(2, cfg.min_views)) return false;
  double se = 0;
  std::uint32_t views = 0;
  for (int i = 0; i < n; ++i)
    if (fin & (1u << i)) {
      const double e = reproj_px(cams[obs[i].camera], obs[i], X);
      se += e * e;
      views |= 1u << obs[i].camera;
    }
  out.world_mm = X;
  out.inliers = __builtin_popcount(fin);
  out.rms_px = std::sqrt(se / out.inliers);
  out.views = views;
  return true;
}

}  // namespace crease::vision
