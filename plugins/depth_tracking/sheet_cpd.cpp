#include "plugins/depth_tracking/sheet_cpd.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "core/errors.h"

namespace crease::depth {
namespace {

void check(bool ok, const char* key, const std::string& reason) {
  if (!ok) throw ConfigError(std::string("depth_tracking: ") + key + ": " + reason);
}

std::uint32_t bucket_of(std::int32_t cx, std::int32_t cy, std::int32_t cz, int buckets) noexcept {
  const auto h = static_cast<std::uint32_t>(cx) * 73856093u ^ static_cast<std::uint32_t>(cy) * 19349663u ^
                 static_cast<std::uint32_t>(cz) * 83492791u;
  return h & static_cast<std::uint32_t>(buckets - 1);
}

}  // namespace

void SheetCpd::configure(const CpdParams& p, std::span<const Eigen::Vector2d> uv, int max_points,
                         int rank_max, double eig_tol, double cut) {
  NonRigidCpd validate;  // the same ranges as the textbook solver, with the same messages
  validate.configure(p, 1, 1);
  const int m = static_cast<int>(uv.size());
  check(m >= 1 && m <= 4096, "nodes", "must be 1 to 4096");
  check(max_points >= 1 && max_points <= 10000000, "max_points", "must be in [1, 1e7]");
  check(rank_max >= 1, "kernel_rank", "must be >= 1");
  check(cut >= 4.0 && cut <= 700.0, "kernel_cut", "must be in [4, 700]");
  cut_ = cut;
  params_ = p;
  m_ = m;
  max_points_ = max_points;
  Eigen::MatrixXd g(m, m);
  const double inv2b = 1.0 / (2.0 * p.beta_mm * p.beta_mm);
  for (int i = 0; i < m; ++i)
    for (int k = 0; k < m; ++k) g(i, k) = std::exp(-(uv[i] - uv[k]).squaredNorm() * inv2b);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(g);
  check(es.info() == Eigen::Success, "beta_mm", "the kernel's eigendecomposition failed");
  // Eigen sorts ascending: keep the largest.
  const Eigen::VectorXd& ev = es.eigenvalues();
  const double top = ev[m - 1];
  int k = 0;
  while (k < std::min(rank_max, m) && ev[m - 1 - k] > eig_tol * top) ++k;
  rank_ = std::max(k, 1);
  q_.resize(m, rank_);
  lambda_.resize(rank_);
  for (int j = 0; j < rank_; ++j) {
    q_.col(j) = es.eigenvectors().col(m - 1 - j);
    lambda_[j] = ev[m - 1 - j];
  }
  a_.resize(m, rank_);
  s_.resize(rank_, rank_);
  qb_.resize(rank_, 3);
  x_.assign(3 * static_cast<std::size_t>(max_points), 0.0);
  for (auto* v : {&y0_, &y_, &px_, &b_}) v->assign(3 * static_cast<std::size_t>(m), 0.0);
  p1_.assign(m, 0.0);
  active_.assign(m, 1);
  act_idx_.assign(m, 0);
  bucket_start_.assign(kBuckets + 1, 0);
  bucket_nodes_.assign(m, 0);
  node_cell_.assign(3 * static_cast<std::size_t>(m), 0);
  point_cell_.assign(3 * static_cast<std::size_t>(max_points), 0);
  point_start_.assign(kBuckets + 1, 0);
  point_order_.assign(static_cast<std::size_t>(max_points), 0);
  cand_.assign(3 * static_cast<std::size_t>(m), 0.0);
  cand_idx_.assign(m, 0);
  cand_e_.assign(m, 0.0);
  near_idx_.assign(m, 0);
  near_k_.assign(m, 0.0);
  // The nodes' mean spacing on the sheet (a grid's pitch).
  Eigen::Vector2d lo = uv[0], hi = uv[0];
  for (const auto& q : uv) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  const Eigen::Vector2d ext = hi - lo;
  min_cell_mm_ = ext.x() > 0.0 && ext.y() > 0.0 ? std::sqrt(ext.x() * ext.y() / m) : ext.maxCoeff() / std::max(1, m - 1);
  min_cell_mm_ = std::max(min_cell_mm_, 1e-3);
}

void SheetCpd::build_grid(double cell, int n) noexcept {
  cell_mm_ = cell;
  const double inv = 1.0 / cell;
  std::fill(bucket_start_.begin(), bucket_start_.end(), 0);
  for (int a = 0; a < n_active_; ++a) {
    const int i = act_idx_[a];
    for (int c = 0; c < 3; ++c)
      node_cell_[3 * i + c] = static_cast<std::int32_t>(std::floor(y_[3 * i + c] * inv));
    ++bucket_start_[bucket_of(node_cell_[3 * i], node_cell_[3 * i + 1], node_cell_[3 * i + 2], kBuckets) + 1];
  }
  for (int b = 0; b < kBuckets; ++b) bucket_start_[b + 1] += bucket_start_[b];
  // Fill (bucket_start_ used as cursors, then shifted back).
  for (int a = 0; a < n_active_; ++a) {
    const int i = act_idx_[a];
    const auto b = bucket_of(node_cell_[3 * i], node_cell_[3 * i + 1], node_cell_[3 * i + 2], kBuckets);
    bucket_nodes_[bucket_start_[b]++] = i;
  }
  for (int b = kBuckets; b > 0; --b) bucket_start_[b] = bucket_start_[b - 1];
  bucket_start_[0] = 0;
  // The points by bucket (stable: in their order inside a bucket), the same way.
  std::fill(point_start_.begin(), point_start_.end(), 0);
  for (int j = 0; j < n; ++j) {
    for (int c = 0; c < 3; ++c)
      point_cell_[3 * j + c] = static_cast<std::int32_t>(std::floor(x_[3 * j + c] * inv));
    ++point_start_[bucket_of(point_cell_[3 * j], point_cell_[3 * j + 1], point_cell_[3 * j + 2], kBuckets) + 1];
  }
  for (int b = 0; b < kBuckets; ++b) point_start_[b + 1] += point_start_[b];
  for (int j = 0; j < n; ++j) {
    const auto b = bucket_of(point_cell_[3 * j], point_cell_[3 * j + 1], point_cell_[3 * j + 2], kBuckets);
    point_order_[point_start_[b]++] = j;
  }
}

int SheetCpd::gather(std::int32_t cx, std::int32_t cy, std::int32_t cz) noexcept {
  double* const px = cand_.data();
  double* const py = px + m_;
  double* const pz = py + m_;
  int count = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const std::int32_t ux = cx + dx, uy = cy + dy, uz = cz + dz;
        const auto b = bucket_of(ux, uy, uz, kBuckets);
        for (int q = bucket_start_[b]; q < bucket_start_[b + 1]; ++q) {
          const int i = bucket_nodes_[q];
          // Another cell hashed into this bucket: its own visit counts it.
          if (node_cell_[3 * i] != ux || node_cell_[3 * i + 1] != uy || node_cell_[3 * i + 2] != uz) continue;
          px[count] = y_[3 * i];
          py[count] = y_[3 * i + 1];
          pz[count] = y_[3 * i + 2];
          cand_idx_[count++] = i;
        }
      }
  return count;
}

double SheetCpd::e_step(int n, double sigma2) noexcept {
  const double inv2s = 1.0 / (2.0 * sigma2);
  const double w = params_.w;
  const double c = std::pow(2.0 * std::numbers::pi * sigma2, 1.5) * w / (1.0 - w) *
                   static_cast<double>(n_active_) / static_cast<double>(n);
  // Cells of at least the cut-off radius: the 27 around a point's hold every node within it.
  build_grid(std::max(std::sqrt(2.0 * sigma2 * cut_), min_cell_mm_), n);
  for (int a = 0; a < n_active_; ++a) {
    const int i = act_idx_[a];
    p1_[i] = 0.0;
    px_[3 * i] = px_[3 * i + 1] = px_[3 * i + 2] = 0.0;
  }
  const double* const cx = cand_.data();
  const double* const cy = cx + m_;
  const double* const cz = cy + m_;
  double* const ce = cand_e_.data();
  double neg_log = 0.0, xpx = 0.0;
  int candidates = 0;
  bool gathered = false;
  std::int32_t gx = 0, gy = 0, gz = 0;  // the cell whose candidates are gathered
  for (int q = 0; q < n; ++q) {
    const int j = point_order_[q];
    const std::int32_t* const cell = &point_cell_[3 * j];
    if (!gathered || cell[0] != gx || cell[1] != gy || cell[2] != gz) {
      gx = cell[0], gy = cell[1], gz = cell[2];
      candidates = gather(gx, gy, gz);
      gathered = true;
    }
    const double xx = x_[3 * j], xy = x_[3 * j + 1], xz = x_[3 * j + 2];
    for (int a = 0; a < candidates; ++a) {
      const double ex = xx - cx[a], ey = xy - cy[a], ez = xz - cz[a];
      ce[a] = (ex * ex + ey * ey + ez * ez) * inv2s;
    }
    int near = 0;
    double den = c;
    for (int a = 0; a < candidates; ++a) {
      if (ce[a] >= cut_) continue;
      const double k = std::exp(-ce[a]);
      near_idx_[near] = cand_idx_[a];
      near_k_[near++] = k;
      den += k;
    }
    if (!(den > 0.0)) den = std::numeric_limits<double>::min();
    const double inv = 1.0 / den;
    double col = 0.0;
    for (int k = 0; k < near; ++k) {
      const int i = near_idx_[k];
      const double pij = near_k_[k] * inv;
      col += pij;
      p1_[i] += pij;
      px_[3 * i] += pij * xx;
      px_[3 * i + 1] += pij * xy;
      px_[3 * i + 2] += pij * xz;
    }
    xpx += col * (xx * xx + xy * xy + xz * xz);
    neg_log -= std::log(den);
  }
  xpx_ = xpx;
  return neg_log;
}

CpdResult SheetCpd::register_cloud(std::span<const Eigen::Vector3d> nodes, std::span<const std::uint8_t> active,
                                   std::span<const Eigen::Vector3d> cloud, std::span<Eigen::Vector3d> out,
                                   std::span<double> support) noexcept {
  CpdResult r;
  const int m = m_;
  if (m < 1 || static_cast<int>(nodes.size()) != m || out.size() != nodes.size() ||
      (!active.empty() && active.size() != nodes.size()) ||
      (!support.empty() && support.size() != nodes.size()) || cloud.empty()) {
    return r;
  }
  const std::size_t total = cloud.size();
  const std::size_t stride = (total + static_cast<std::size_t>(max_points_) - 1) / static_cast<std::size_t>(max_points_);
  int n = 0;
  for (std::size_t s = 0; s < total && n < max_points_; s += stride, ++n)
    for (int c = 0; c < 3; ++c) x_[3 * static_cast<std::size_t>(n) + c] = cloud[s][c];
  r.points_used = n;
  r.points_dropped = static_cast<std::int32_t>(total - static_cast<std::size_t>(n));
  n_active_ = 0;
  for (int i = 0; i < m; ++i) {
    active_[i] = active.empty() ? 1 : (active[i] != 0 ? 1 : 0);
    if (active_[i]) act_idx_[n_active_++] = i;
    p1_[i] = 0.0;
    for (int c = 0; c < 3; ++c) {
      y0_[3 * i + c] = y_[3 * i + c] = nodes[static_cast<std::size_t>(i)][c];
      px_[3 * i + c] = 0.0;
    }
  }
  if (n_active_ == 0) return r;

  double sigma2 = params_.sigma2_init_mm2;
  if (sigma2 <= 0.0) {  // (1/(D M N)) sum |x - y|^2 over the active nodes, from the moments
    double sx[3] = {0, 0, 0}, sy[3] = {0, 0, 0}, xx = 0, yy = 0;
    for (int j = 0; j < n; ++j)
      for (int c = 0; c < 3; ++c) {
        sx[c] += x_[3 * j + c];
        xx += x_[3 * j + c] * x_[3 * j + c];
      }
    for (int a = 0; a < n_active_; ++a)
      for (int c = 0; c < 3; ++c) {
        const double v = y0_[3 * act_idx_[a] + c];
        sy[c] += v;
        yy += v * v;
      }
    sigma2 = (n_active_ * xx + n * yy - 2.0 * (sx[0] * sy[0] + sx[1] * sy[1] + sx[2] * sy[2])) /
             (3.0 * n_active_ * n);
  }
  sigma2 = std::max(sigma2, params_.sigma2_min_mm2);
  const double lambda_mm = params_.lambda / (kLambdaScaleMm * kLambdaScaleMm);
  const int k = rank_;
  double objective_old = 0.0;
  bool have_old = false;
  double reg = 0.0;  // tr(W^T G W) of the last M-step (W = 0 before the first)
  for (int it = 0; it < params_.max_iterations; ++it) {
    const double neg_log = e_step(n, sigma2);
    double np = 0.0;
    for (int a = 0; a < n_active_; ++a) np += p1_[act_idx_[a]];
    if (!(np > 0.0)) np = 1e-12;
    const double objective = neg_log + 1.5 * np * std::log(sigma2) + 0.5 * lambda_mm * reg;
    r.iterations = it + 1;
    if (have_old && std::abs(objective - objective_old) <= params_.tolerance * std::abs(objective)) {
      r.converged = true;
      break;
    }
    objective_old = objective;
    have_old = true;

    // M-step (Woodbury): with d = P1 / (lambda' sigma^2), B' = (PX - d(P1) Y0) / (lambda' sigma^2),
    // S = L^-1 + Q^T d Q and z = S^-1 Q^T B': Y = Y0 + Q z (header).
    const double inv_ls = 1.0 / (lambda_mm * sigma2);
    int rows = 0;
    for (int i = 0; i < m; ++i) {
      for (int c = 0; c < 3; ++c) b_[3 * i + c] = (px_[3 * i + c] - p1_[i] * y0_[3 * i + c]) * inv_ls;
      if (p1_[i] > 0.0) a_.row(rows++) = std::sqrt(p1_[i] * inv_ls) * q_.row(i);
    }
    s_.setZero();
    s_.selfadjointView<Eigen::Lower>().rankUpdate(a_.topRows(rows).transpose());
    for (int j = 0; j < k; ++j) s_(j, j) += 1.0 / lambda_[j];
    Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> bm(b_.data(), m, 3);
    qb_.noalias() = q_.transpose() * bm;
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> llt(s_);
    if (llt.info() != Eigen::Success) return r;
    llt.solveInPlace(qb_);
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> ym(y_.data(), m, 3);
    Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> y0m(y0_.data(), m, 3);
    ym = y0m;
    ym.noalias() += q_ * qb_;
    reg = 0.0;
    for (int j = 0; j < k; ++j) reg += qb_.row(j).squaredNorm() / lambda_[j];
    // sigma^2 over the active nodes.
    double pxy = 0.0, ypy = 0.0;
    for (int a = 0; a < n_active_; ++a) {
      const int i = act_idx_[a];
      for (int c = 0; c < 3; ++c) {
        pxy += px_[3 * i + c] * y_[3 * i + c];
        ypy += p1_[i] * y_[3 * i + c] * y_[3 * i + c];
      }
    }
    sigma2 = std::max((xpx_ - 2.0 * pxy + ypy) / (3.0 * np), params_.sigma2_min_mm2);
  }
  for (int i = 0; i < m; ++i) {
    out[static_cast<std::size_t>(i)] = Eigen::Vector3d(y_[3 * i], y_[3 * i + 1], y_[3 * i + 2]);
    if (!support.empty()) support[static_cast<std::size_t>(i)] = p1_[i];
  }
  r.sigma2_mm2 = sigma2;
  r.ok = true;
  return r;
}

}  // namespace crease::depth
