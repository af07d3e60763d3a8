// Non-rigid Coherent Point Drift (Myronenko & Song 2010, "Point Set Registration: Coherent
// Point Drift", Fig. 4) with the sheet model's nodes as the Gaussian centroids (warm start).
//
// The centroids Y0 (M nodes, world mm) move to Y = Y0 + G W, G_ij = exp(-|y0_i - y0_j|^2 /
// (2 beta^2)), so as to maximise the likelihood of the cloud X (N points, world mm) under a
// mixture of M isotropic Gaussians of variance sigma^2 plus a uniform outlier term of weight w,
// penalised by lambda'/2 tr(W^T G W) (lambda' = lambda / kLambdaScaleMm^2) (motion coherence). Every iteration: the E-step (posteriors
// P_mn, direct O(M N), never stored), the M-step (W from (G + lambda' sigma^2 d(P1)^-1) W =
// d(P1)^-1 P X - Y0 by an in-place Cholesky), then sigma^2 from its closed-form update; it stops
// when the objective's relative change falls below `tolerance` or after `max_iterations`.
//
// configure() sizes every buffer for max_nodes and max_points; register_cloud() allocates
// nothing, takes no lock and throws nothing. A cloud larger than max_points is thinned by a
// fixed stride (deterministic), the points left out counted in the result.
#pragma once

#include <cstdint>
#include <span>

#include <Eigen/Core>
#include <Eigen/Cholesky>

namespace crease::depth {

inline constexpr double kLambdaScaleMm = 100.0;  // ~ the RMS radius of an A4 sheet's nodes

struct CpdParams {
  double beta_mm = 40.0;          // Gaussian kernel width of G, mm (0.5 .. 1000)
  // Motion coherence regulariser (1e-3 .. 1e3): the paper's lambda, which acts on coordinates
  // normalised to unit variance, here for coordinates in units of kLambdaScaleMm (the solver
  // uses lambda / kLambdaScaleMm^2 per mm^2), so its stiffness does not change as the sheet folds.
  double lambda = 2.0;
  double w = 0.1;                 // outlier weight, [0, 0.99]
  int max_iterations = 100;       // per call
  double tolerance = 1e-6;        // relative change of the objective that ends the iterations
  // Initial sigma^2, mm^2: the warm start is the model's prediction, ~10 mm off. 0: the paper's
  // (1/(D M N)) sum |x_n - y_m|^2, for a cold start (shrinks the grid first, converges slower).
  double sigma2_init_mm2 = 100.0;
  // Floor of sigma^2, mm^2 (~ the depth noise): without it sigma^2 collapses onto single
  // points (M << N) and the outlier term swallows the rest.
  double sigma2_min_mm2 = 1.0;
};

struct CpdResult {
  int iterations = 0;
  double sigma2_mm2 = 0.0;        // final variance
  bool converged = false;         // objective change below tolerance before max_iterations
  std::int32_t points_used = 0;   // N after thinning
  std::int32_t points_dropped = 0;  // points a too-large cloud lost to thinning
  bool ok = false;                // false: no node, no point, or a non-positive-definite solve
};

class NonRigidCpd {
 public:
  using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  // rows: x y z mm

  // Non-RT: validates (crease::ConfigError naming the field) and sizes every buffer.
  void configure(const CpdParams& params, int max_nodes, int max_points);

  // RT-safe after configure (no allocation, lock or throw). nodes: Y0, cloud: X, both world
  // mm. Writes the registered node positions Y into `out` (size of nodes) and, when `support`
  // is not empty (size of nodes), each node's posterior support P1_m = sum_n P_mn (the expected
  // number of cloud points it explains). More nodes than max_nodes: ok = false, nothing written.
  CpdResult register_cloud(std::span<const Eigen::Vector3d> nodes,
                           std::span<const Eigen::Vector3d> cloud,
                           std::span<Eigen::Vector3d> out,
                           std::span<double> support = {}) noexcept;

  [[nodiscard]] const CpdParams& params() const noexcept { return params_; }
  [[nodiscard]] int max_nodes() const noexcept { return max_nodes_; }
  [[nodiscard]] int max_points() const noexcept { return max_points_; }

 private:
  double e_step(int m, int n, double sigma2) noexcept;  // returns -sum_n log(denominator)

  CpdParams params_;
  int max_nodes_ = 0;
  int max_points_ = 0;
  Points x_, y0_, y_, px_, w_;  // capacity rows; the first N / M rows are used
  Eigen::MatrixXd g_;           // M x M kernel (top-left block)
  Eigen::MatrixXd a_;           // M x M system matrix, factorised in place
  Eigen::VectorXd p1_, pt1_, k_;  // P1 (M), Pt1 (N), one column of kernel values (M)
};

}  // namespace crease::depth
