#include "plugins/depth_tracking/cpd.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "core/errors.h"

namespace crease::depth {
namespace {

constexpr double kMinP1 = 1e-12;
// Kernel values below exp(-40) (4e-18, below double rounding of any sum with a nearer node or
// the outlier term) are taken as zero without calling exp: most node-point pairs of a sheet.
// (With w = 0 a point farther than that from every node then has no posterior at all.)
constexpr double kMaxExponent = 40.0;  // a node no point supports gets a huge d(P1)^-1, W_m ~ 0

void check(bool ok, const char* key, const std::string& reason) {
  if (!ok) throw ConfigError(std::string("depth_tracking: ") + key + ": " + reason);
}

}  // namespace

void NonRigidCpd::configure(const CpdParams& p, int max_nodes, int max_points) {
  check(p.beta_mm >= 0.5 && p.beta_mm <= 1000.0, "beta_mm", "must be in [0.5, 1000]");
  check(p.lambda >= 1e-3 && p.lambda <= 1e3, "lambda", "must be in [0.001, 1000]");
  check(p.w >= 0.0 && p.w <= 0.99, "w", "must be in [0, 0.99]");
  check(p.max_iterations >= 1 && p.max_iterations <= 1000, "max_iterations", "must be in [1, 1000]");
  check(p.tolerance > 0.0 && p.tolerance < 1.0, "tolerance", "must be in (0, 1)");
  check(p.sigma2_init_mm2 >= 0.0, "sigma2_init_mm2", "must be >= 0");
  check(p.sigma2_min_mm2 > 0.0, "sigma2_min_mm2", "must be > 0");
  check(max_nodes >= 1 && max_nodes <= 20000, "max_nodes", "must be in [1, 20000]");
  check(max_points >= 1 && max_points <= 10000000, "max_points", "must be in [1, 1e7]");
  params_ = p;
  max_nodes_ = max_nodes;
  max_points_ = max_points;
  x_.resize(max_points, 3);
  pt1_.resize(max_points);
  y0_.resize(max_nodes, 3);
  y_.resize(max_nodes, 3);
  px_.resize(max_nodes, 3);
  w_.resize(max_nodes, 3);
  p1_.resize(max_nodes);
  k_.resize(max_nodes);
  g_.resize(max_nodes, max_nodes);
  a_.resize(max_nodes, max_nodes);
}

// E-step for the current Y (first m rows of y_): P1, Pt1, PX. Each point's column of kernel
// values is computed once into k_, its denominator summed, then accumulated (P never stored).
double NonRigidCpd::e_step(int m, int n, double sigma2) noexcept {
  const double inv2s = 1.0 / (2.0 * sigma2);
  const double w = params_.w;
  const double c = std::pow(2.0 * std::numbers::pi * sigma2, 1.5) * w / (1.0 - w) *
                   static_cast<double>(m) / static_cast<double>(n);
  p1_.head(m).setZero();
  px_.topRows(m).setZero();
  double neg_log = 0.0;
  for (int j = 0; j < n; ++j) {
    const double xx = x_(j, 0), xy = x_(j, 1), xz = x_(j, 2);
    double den = c;
    for (int i = 0; i < m; ++i) {
      const double dx = xx - y_(i, 0), dy = xy - y_(i, 1), dz = xz - y_(i, 2);
      const double e = (dx * dx + dy * dy + dz * dz) * inv2s;
      const double k = e < kMaxExponent ? std::exp(-e) : 0.0;
      k_[i] = k;
      den += k;
    }
    if (!(den > 0.0)) den = std::numeric_limits<double>::min();  // w = 0 and every k underflowed
    const double inv = 1.0 / den;
    double col = 0.0;
    for (int i = 0; i < m; ++i) {
      const double pij = k_[i] * inv;
      col += pij;
      p1_[i] += pij;
      px_(i, 0) += pij * xx;
      px_(i, 1) += pij * xy;
      px_(i, 2) += pij * xz;
    }
    pt1_[j] = col;
    neg_log -= std::log(den);
  }
  return neg_log;
}

CpdResult NonRigidCpd::register_cloud(std::span<const Eigen::Vector3d> nodes,
                                      std::span<const Eigen::Vector3d> cloud,
                                      std::span<Eigen::Vector3d> out,
                                      std::span<double> support) noexcept {
  CpdResult r;
  const int m = static_cast<int>(nodes.size());
  if (m < 1 || m > max_nodes_ || out.size() != nodes.size() ||
      (!support.empty() && support.size() != nodes.size()) || cloud.empty()) {
    return r;
  }
  // Thinning: every stride-th point, at most max_points of them.
  const std::size_t total = cloud.size();
  const std::size_t stride = (total + static_cast<std::size_t>(max_points_) - 1) /
                             static_cast<std::size_t>(max_points_);
  int n = 0;
  for (std::size_t s = 0; s < total && n < max_points_; s += stride, ++n) {
    x_.row(n) = cloud[s].transpose();
  }
  r.points_used = n;
  r.points_dropped = static_cast<std::int32_t>(total - static_cast<std::size_t>(n));
  for (int i = 0; i < m; ++i) y0_.row(i) = nodes[static_cast<std::size_t>(i)].transpose();

  // G from the centroids Y0.
  const double inv2b = 1.0 / (2.0 * params_.beta_mm * params_.beta_mm);
  for (int i = 0; i < m; ++i) {
    g_(i, i) = 1.0;
    for (int k = i + 1; k < m; ++k) {
      const double d2 = (y0_.row(i) - y0_.row(k)).squaredNorm();
      g_(i, k) = g_(k, i) = std::exp(-d2 * inv2b);
    }
  }

  // sigma^2 initial: (1/(D M N)) sum_mn |x_n - y_m|^2 in O(M + N) from first and second moments.
  double sigma2 = params_.sigma2_init_mm2;
  if (sigma2 <= 0.0) {
    const Eigen::RowVector3d sx = x_.topRows(n).colwise().sum();
    const Eigen::RowVector3d sy = y0_.topRows(m).colwise().sum();
    const double xx = x_.topRows(n).squaredNorm(), yy = y0_.topRows(m).squaredNorm();
    sigma2 = (m * xx + n * yy - 2.0 * sx.dot(sy)) / (3.0 * m * n);
  }
  sigma2 = std::max(sigma2, params_.sigma2_min_mm2);

  y_.topRows(m) = y0_.topRows(m);
  w_.topRows(m).setZero();
  const double lambda_mm = params_.lambda / (kLambdaScaleMm * kLambdaScaleMm);  // mm^-2
  double objective_old = 0.0;
  bool have_old = false;
  for (int it = 0; it < params_.max_iterations; ++it) {
    const double neg_log = e_step(m, n, sigma2);
    double np = p1_.head(m).sum();
    if (!(np > 0.0)) np = kMinP1;
    // Objective of the current (W, sigma^2): the negative log-likelihood (up to a constant)
    // plus lambda/2 tr(W^T G W), tr(W^T G W) = tr(W^T (Y - Y0)).
    const double reg = (w_.topRows(m).cwiseProduct(y_.topRows(m) - y0_.topRows(m))).sum();
    const double objective = neg_log + 1.5 * np * std::log(sigma2) + 0.5 * lambda_mm * reg;
    r.iterations = it + 1;
    if (have_old && std::abs(objective - objective_old) <= params_.tolerance * std::abs(objective)) {
      r.converged = true;
      break;
    }
    objective_old = objective;
    have_old = true;

    // M-step: (G + lambda' sigma^2 d(P1)^-1) W = d(P1)^-1 PX - Y0, symmetric positive definite.
    auto a = a_.topLeftCorner(m, m);
    a = g_.topLeftCorner(m, m);
    for (int i = 0; i < m; ++i) {
      const double inv_p1 = 1.0 / std::max(p1_[i], kMinP1);
      a(i, i) += lambda_mm * sigma2 * inv_p1;
      w_.row(i) = px_.row(i) * inv_p1 - y0_.row(i);
    }
    Eigen::Ref<Eigen::MatrixXd> a_ref(a);
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(a_ref);
    if (llt.info() != Eigen::Success) return r;
    auto wm = w_.topRows(m);
    llt.solveInPlace(wm);
    // Y = Y0 + G W (written out: no product temporaries).
    for (int i = 0; i < m; ++i) {
      double s0 = 0.0, s1 = 0.0, s2 = 0.0;
      for (int k = 0; k < m; ++k) {
        const double g = g_(k, i);  // symmetric; column access is contiguous
        s0 += g * w_(k, 0);
        s1 += g * w_(k, 1);
        s2 += g * w_(k, 2);
      }
      y_(i, 0) = y0_(i, 0) + s0;
      y_(i, 1) = y0_(i, 1) + s1;
      y_(i, 2) = y0_(i, 2) + s2;
    }
    // sigma^2 = (tr(X^T d(Pt1) X) - 2 tr((PX)^T Y) + tr(Y^T d(P1) Y)) / (Np D).
    double xpx = 0.0;
    for (int j = 0; j < n; ++j) xpx += pt1_[j] * x_.row(j).squaredNorm();
    double pxy = 0.0, ypy = 0.0;
    for (int i = 0; i < m; ++i) {
      pxy += px_.row(i).dot(y_.row(i));
      ypy += p1_[i] * y_.row(i).squaredNorm();
    }
    sigma2 = std::max((xpx - 2.0 * pxy + ypy) / (3.0 * np), params_.sigma2_min_mm2);
  }
  for (int i = 0; i < m; ++i) {
    out[static_cast<std::size_t>(i)] = y_.row(i).transpose();
    if (!support.empty()) support[static_cast<std::size_t>(i)] = p1_[i];
  }
  r.sigma2_mm2 = sigma2;
  r.ok = true;
  return r;
}

}  // namespace crease::depth
