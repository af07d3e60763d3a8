// Textbook non-rigid CPD (Myronenko & Song 2010, Fig. 4) for the tests: the full M x N posterior
// matrix P, the kernel G, and the M-step in the paper's own form (d(P1) G + lambda sigma^2 I) W
// = P X - d(P1) Y0 solved by LU. Same initial sigma^2, objective and stopping rule as
// crease::depth::NonRigidCpd, written independently of it.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Dense>

#include "plugins/depth_tracking/cpd.h"

namespace crease::depth::test {

struct DenseResult {
  Eigen::MatrixXd y;  // M x 3
  Eigen::VectorXd p1;
  int iterations = 0;
};

inline DenseResult dense_cpd(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y0, const CpdParams& p) {
  const auto m = y0.rows(), n = x.rows();
  Eigen::MatrixXd g(m, m);
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index k = 0; k < m; ++k)
      g(i, k) = std::exp(-(y0.row(i) - y0.row(k)).squaredNorm() / (2.0 * p.beta_mm * p.beta_mm));
  double sigma2 = p.sigma2_init_mm2;
  if (sigma2 <= 0.0) {
    double s = 0.0;
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = 0; i < m; ++i) s += (x.row(j) - y0.row(i)).squaredNorm();
    sigma2 = s / (3.0 * static_cast<double>(m * n));
  }
  sigma2 = std::max(sigma2, p.sigma2_min_mm2);
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(m, 3), y = y0, pm(m, n);
  Eigen::VectorXd p1;
  DenseResult r;
  const double lambda = p.lambda / (kLambdaScaleMm * kLambdaScaleMm);
  double old = 0.0;
  for (int it = 0; it < p.max_iterations; ++it) {
    const double c = std::pow(2.0 * std::numbers::pi * sigma2, 1.5) * p.w / (1.0 - p.w) *
                     static_cast<double>(m) / static_cast<double>(n);
    double neg_log = 0.0;
    for (Eigen::Index j = 0; j < n; ++j) {
      for (Eigen::Index i = 0; i < m; ++i)
        pm(i, j) = std::exp(-(x.row(j) - y.row(i)).squaredNorm() / (2.0 * sigma2));
      const double den = pm.col(j).sum() + c;
      pm.col(j) /= den;
      neg_log -= std::log(den);
    }
    p1 = pm.rowwise().sum();
    const Eigen::VectorXd pt1 = pm.colwise().sum().transpose();
    const Eigen::MatrixXd px = pm * x;
    const double np = p1.sum();
    const double objective = neg_log + 1.5 * np * std::log(sigma2) +
                             0.5 * lambda * (w.transpose() * g * w).trace();
    r.iterations = it + 1;
    if (it > 0 && std::abs(objective - old) <= p.tolerance * std::abs(objective)) break;
    old = objective;
    const Eigen::MatrixXd a = p1.asDiagonal() * g + lambda * sigma2 * Eigen::MatrixXd::Identity(m, m);
    w = a.partialPivLu().solve(px - p1.asDiagonal() * y0);
    y = y0 + g * w;
    const double xpx = (pt1.asDiagonal() * x).cwiseProduct(x).sum();
    const double pxy = px.cwiseProduct(y).sum();
    const double ypy = (p1.asDiagonal() * y).cwiseProduct(y).sum();
    sigma2 = std::max((xpx - 2.0 * pxy + ypy) / (3.0 * np), p.sigma2_min_mm2);
  }
  r.y = y;
  r.p1 = p1;
  return r;
}

}  // namespace crease::depth::test
