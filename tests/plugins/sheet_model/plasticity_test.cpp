// Elasto-plastic links against the analytic 1D bilinear kinematic-hardening law
// (return mapping in stress space, Simo & Hughes 1998 box 1.4), through the solver.
#include "plugins/sheet_model/plasticity.h"
#include "plugins/sheet_model/xpbd_sheet.h"

#include <doctest/doctest.h>

#include <cmath>
#include <vector>

using namespace crease::sheet;

namespace {

// Analytic law: stress s = E (eps - eps_p), back stress q = H eps_p, yield |s - q| <= E eps_Y;
// the plasticity rate of seed 001 is a = E / (E + H).
struct Bilinear {
  double E = 1.0, H, sy, eps_p = 0;
  Bilinear(double a, double eps_y) : H(E * (1 - a) / a), sy(E * eps_y) {}
  void load(double eps) {
    const double xi = E * (eps - eps_p) - H * eps_p;
    const double f = std::fabs(xi) - sy;
    if (f > 0) eps_p += (xi > 0 ? 1 : -1) * f / (E + H);
  }
};

}  // namespace

TEST_CASE("plastic_update follows the three rules of seed 001 III.C") {
  const double a = 0.4, y = 0.1;
  CHECK(plastic_update(0.05, 0.0, a, y) == 0.0);                  // elastic
  CHECK(plastic_update(0.3, 0.0, a, y) == doctest::Approx(0.08));  // a * (0.3 - 0.1)
  CHECK(plastic_update(-0.3, 0.0, a, y) == doctest::Approx(-0.08));
  CHECK(plastic_update(0.3, 0.0, 0.0, y) == 0.0);  // a = 0 disables plasticity
}

TEST_CASE("elasto-plastic links reproduce bilinear kinematic hardening: load, unload, reverse") {
  SheetParams p;
  p.grid.nodes_u = 2;
  p.grid.nodes_v = 2;
  p.grid.width_mm = 10;
  p.grid.height_mm = 10;
  p.topology.diagonals = Diagonals::none;
  p.topology.bend_box_radius = 0;
  p.solver.gravity_mm_per_s2 = {0, 0, 0};
  p.solver.plasticity_rate = 0.3;
  p.solver.yield_strain = 0.01;
  p.solver.plastic_bending_only = false;
  p.solver.substeps = 3;
  XpbdSheet s(p);
  // Link 0 joins node 0 and node 1 (rest 10 mm along u). Pin all nodes; drive node 1.
  REQUIRE(s.topology().a[0] == 0);
  REQUIRE(s.topology().b[0] == 1);
  const double l = s.rest_lengths()[0];
  REQUIRE(l == doctest::Approx(10.0));
  for (int i = 0; i < s.node_count(); ++i) s.pin(i, s.positions()[i]);
  const Vec3 x0 = s.positions()[0];
  const Vec3 dir = crease::sheet::normalized(s.positions()[1] - x0);

  Bilinear law(p.solver.plasticity_rate, p.solver.yield_strain);
  // Strain path: load to +5 %, unload to 0, reverse to -4 %, reload to +2 %, in uneven steps.
  std::vector<double> path;
  auto ramp = [&path](double from, double to, int n) {
    for (int k = 1; k <= n; ++k) path.push_back(from + (to - from) * k / n);
  };
  ramp(0, 0.05, 37);
  ramp(0.05, 0.0, 11);
  ramp(0.0, -0.04, 23);
  ramp(-0.04, 0.02, 7);
  double max_err = 0;
  bool saw_plastic_unload_elastic = false;
  for (double eps : path) {
    s.pin(1, x0 + (l * (1 + eps)) * dir);
    s.step_rt(1.0 / 60);
    law.load(eps);
    const double err = std::fabs(s.plastic_elongations()[0] - law.eps_p * l);
    max_err = std::max(max_err, err);
    if (eps == 0.0 && law.eps_p > 0) saw_plastic_unload_elastic = true;
  }
  MESSAGE("max |dl_p - analytic| = " << max_err << " mm");
  CHECK(max_err < 1e-9);
  CHECK(saw_plastic_unload_elastic);
  // The law itself: after +5 %, -4 %, +2 % the analytic permanent strain is known in closed form.
  const double a = 0.3, ey = 0.01;
  const double after_load = a * (0.05 - ey);
  const double after_reverse = after_load + a * (-0.04 - (after_load / a - ey));
  const double after_reload = after_reverse + a * (0.02 - (after_reverse / a + ey));
  CHECK(after_reverse < 0);  // the reverse load yielded in compression
  CHECK(law.eps_p == doctest::Approx(after_reload).epsilon(1e-12));
  CHECK(s.plastic_elongations()[0] == doctest::Approx(after_reload * l).epsilon(1e-9));
}
