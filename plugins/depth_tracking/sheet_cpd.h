// Non-rigid Coherent Point Drift of the sheet model's nodes onto a depth cloud, made fast enough
// for every frame by three choices (against cpd.h's textbook form, which it matches when every
// node is active, the kernel is taken from the same coordinates and the rank is full):
//  - the motion-coherence kernel on the nodes' SHEET coordinates, G_ij = exp(-|uv_i - uv_j|^2 /
//    (2 beta^2)) (the material, not the world positions): it is fixed for the sheet, so its
//    low-rank eigendecomposition G ~ Q L Q^T (rank K, Myronenko & Song 2010 Sec. 5's fast
//    variant) is computed once at configure; and two layers lying on each other (a fold) are
//    not coupled by it;
//  - the M-step by the Woodbury identity, (G + lambda' sigma^2 d(P1)^-1)^-1 in O(M K^2 + K^3)
//    instead of an M x M Cholesky; a node with P1 = 0 needs no special case. With
//    S = L^-1 + Q^T d Q (d = P1 / (lambda' sigma^2)) and z = S^-1 Q^T B', Q^T W = L^-1 z, so
//    Y = Y0 + Q z and tr(W^T G W) = tr(z^T L^-1 z): W itself is never formed, and Q^T d Q is a
//    symmetric rank update over the nodes with P1 > 0;
//  - the E-step over the ACTIVE nodes only (those some camera sees: visibility.h; the others
//    get P1 = 0, move only with their neighbours through G and get no target), each point
//    visiting the active nodes of the 27 grid cells around it (cells at least the kernel's
//    cut-off radius, rebuilt every iteration): kernel values below exp(-cut) are zero (cpd.h:
//    exp(-40)). The points are taken cell by cell (a counting sort per iteration), so the nodes
//    around a cell are gathered once for all its points.
// configure() allocates everything; register_cloud() allocates nothing, takes no lock, throws
// nothing.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "plugins/depth_tracking/cpd.h"

namespace crease::depth {

class SheetCpd {
 public:
  // Non-RT. sheet_uv: every node's sheet (u, v), mm, in node order; rank_max: the kernel's rank
  // at most (eigenvalues below eig_tol * the largest are dropped too); cut: the exponent beyond
  // which a kernel value is zero (cpd.h's is 40; 20 leaves out values below 2e-9). Throws ConfigError.
  void configure(const CpdParams& params, std::span<const Eigen::Vector2d> sheet_uv, int max_points,
                 int rank_max = 120, double eig_tol = 1e-7, double cut = 20.0);

  // RT-safe. nodes: Y0 (every node, world mm); active: 1 = in the E-step (size of nodes; empty:
  // all); cloud: X (world mm). Writes Y for every node into `out` and P1 into `support` (both
  // the size of nodes; support may be empty). A cloud larger than max_points is thinned by a
  // fixed stride (counted in the result).
  CpdResult register_cloud(std::span<const Eigen::Vector3d> nodes, std::span<const std::uint8_t> active,
                           std::span<const Eigen::Vector3d> cloud, std::span<Eigen::Vector3d> out,
                           std::span<double> support = {}) noexcept;

  [[nodiscard]] int rank() const noexcept { return rank_; }
  [[nodiscard]] int nodes() const noexcept { return m_; }
  [[nodiscard]] const CpdParams& params() const noexcept { return params_; }

 private:
  double e_step(int n, double sigma2) noexcept;  // returns -sum log(denominator); fills p1, px, xpx_
  void build_grid(double cell_mm, int n) noexcept;  // the active nodes' and the n points' cells
  int gather(std::int32_t cx, std::int32_t cy, std::int32_t cz) noexcept;  // candidates around a cell

  CpdParams params_;
  int m_ = 0, max_points_ = 0, rank_ = 0;
  Eigen::MatrixXd q_;       // M x K eigenvectors of G
  Eigen::VectorXd lambda_;  // K eigenvalues
  Eigen::MatrixXd a_, s_;   // rows sqrt(d_i) Q_i of the nodes with P1 > 0 (M x K); S (K x K, lower)
  Eigen::MatrixXd qb_;      // K x 3: Q^T B', then z
  std::vector<double> x_;   // 3 N
  std::vector<double> y0_, y_, px_, b_;  // 3 M
  std::vector<double> p1_;  // M
  std::vector<std::uint8_t> active_;
  std::vector<std::int32_t> act_idx_;  // the active nodes
  int n_active_ = 0;
  double xpx_ = 0.0;        // sum_n Pt1_n |x_n|^2 of the last E-step
  // Uniform grid of the active centroids, hashed into kBuckets buckets (counting sort).
  static constexpr int kBuckets = 4096;
  std::vector<std::int32_t> bucket_start_;  // kBuckets + 1
  std::vector<std::int32_t> bucket_nodes_;  // active nodes by bucket
  std::vector<std::int32_t> node_cell_;     // 3 per node: its cell
  std::vector<std::int32_t> point_cell_;    // 3 per point: its cell
  std::vector<std::int32_t> point_start_;   // kBuckets + 1
  std::vector<std::int32_t> point_order_;   // the points by bucket of their cell
  std::vector<double> cand_;                // 3 per candidate node: its position ...
  std::vector<std::int32_t> cand_idx_;      // ... and its number (the nodes around a cell)
  std::vector<double> cand_e_;              // per candidate: the kernel's exponent for a point
  std::vector<std::int32_t> near_idx_;      // per point: the nodes within the cut-off ...
  std::vector<double> near_k_;              // ... and their kernel values
  double cell_mm_ = 1.0;
  double min_cell_mm_ = 1.0;  // the nodes' mean spacing: smaller cells cost more look-ups than they save
  double cut_ = 20.0;
};

}  // namespace crease::depth
