#include "plugins/depth_tracking/cpd_params.h"

namespace crease::depth {

CpdParams cpd_params_from(const crease::Params& p) {
  const CpdParams d;
  CpdParams c;
  c.beta_mm = p.get_in_range<double>("beta_mm", d.beta_mm, 0.5, 1000.0);
  c.lambda = p.get_in_range<double>("lambda", d.lambda, 1e-3, 1e3);
  c.w = p.get_in_range<double>("w", d.w, 0.0, 0.99);
  c.max_iterations = p.get_in_range<int>("max_iterations", d.max_iterations, 1, 1000);
  c.tolerance = p.get_in_range<double>("tolerance", d.tolerance, 1e-12, 0.5);
  c.sigma2_init_mm2 = p.get_in_range<double>("sigma2_init_mm2", d.sigma2_init_mm2, 0.0, 1e8);
  c.sigma2_min_mm2 = p.get_in_range<double>("sigma2_min_mm2", d.sigma2_min_mm2, 1e-8, 1e4);
  return c;
}

}  // namespace crease::depth
