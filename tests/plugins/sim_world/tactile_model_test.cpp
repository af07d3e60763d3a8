// The simulated tactile sensors: the right hand's taxel matrices read a pressed fingertip's
// force back through their calibration, too light a touch reads nothing (the threshold), and
// the noise comes from the seed; the left hand's PST sensors read kpa_per_n x force, a held
// force decays through their high-pass, and their drift is what a tare removes.
#include "plugins/sim_world/tactile_model.h"

#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "plugins/robot_model/robot_params.h"
#include "rt/alloc_guard.h"

using crease::world::TactileModel;
using crease::robot::TactileParams;

namespace {

const crease::robot::RobotParams& params() {
  static const auto p = crease::robot::load_robot_params(std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml");
  return p;
}
TactileParams right() { return params().sides[0].tactile; }
TactileParams left() { return params().sides[1].tactile; }

// Mean calibrated force of a fingertip pressed with F at (x, y) over N samples.
double mean_taxel_force(TactileModel& m, double f, double x = 0, double y = 0, int n = 200) {
  float kpa[TactileModel::kTaxels];
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    m.taxels_rt(f, x, y, kpa);
    sum += m.taxel_force_n(kpa);
  }
  return sum / n;
}

int lit_taxels(const float* kpa) {
  int n = 0;
  for (int k = 0; k < TactileModel::kTaxels; ++k) n += kpa[k] > 0 ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("taxel layout: 34 taxels at the pitch, centred on the pad") {
  const auto l = TactileModel::layout(3.0);
  double cx = 0, cy = 0;
  for (const auto& t : l) {
    cx += t[0];
    cy += t[1];
  }
  CHECK(cy / 34 == doctest::Approx(0.0).epsilon(1e-12));
  CHECK(cx / 34 < 0.0);  // the missing corners are distal
  CHECK(l[1][1] - l[0][1] == doctest::Approx(3.0));
}

TEST_CASE("taxel matrix: the calibrated sum reads a firm press back, a light touch reads nothing") {
  TactileModel m(right(), 7);
  const double at2 = mean_taxel_force(m, 2.0);
  const double at1 = mean_taxel_force(m, 1.0);
  MESSAGE("calibrated taxel force at 2 N: " << at2 << " N, at 1 N: " << at1 << " N, at 0.5 N: " << mean_taxel_force(m, 0.5)
                                             << " N, at 0.2 N: " << mean_taxel_force(m, 0.2) << " N");
  // taxel_area_mm2 is calibrated so: presses of 0.5 to 2 N at the pad's centre read back.
  CHECK(at2 == doctest::Approx(2.0).epsilon(0.05));
  CHECK(at1 == doctest::Approx(1.0).epsilon(0.05));
  CHECK(mean_taxel_force(m, 0.5) == doctest::Approx(0.5).epsilon(0.05));
  CHECK(mean_taxel_force(m, 0.2) < 0.05);  // limited sensitivity: below the threshold everywhere
  float kpa[TactileModel::kTaxels];
  m.taxels_rt(0.0, 0, 0, kpa);
  CHECK(lit_taxels(kpa) == 0);  // the noise floor (1 kPa) stays below the 8 kPa threshold

  SUBCASE("failing variant: without the threshold the noise floor lights taxels") {
    TactileParams p = right();
    p.taxel.threshold_kpa = 0.0;
    TactileModel raw(p, 7);
    raw.taxels_rt(0.0, 0, 0, kpa);
    CHECK(lit_taxels(kpa) > 5);
  }
}

TEST_CASE("taxel matrix: the contact point moves the lit taxels") {
  TactileModel m(right(), 3);
  float centre[TactileModel::kTaxels], distal[TactileModel::kTaxels];
  m.taxels_rt(2.0, 0, 0, centre);
  m.taxels_rt(2.0, 6.0, 0, distal);
  double xc = 0, xd = 0, wc = 0, wd = 0;
  const auto l = TactileModel::layout(3.0);
  for (int k = 0; k < TactileModel::kTaxels; ++k) {
    xc += centre[k] * l[k][0];
    wc += centre[k];
    xd += distal[k] * l[k][0];
    wd += distal[k];
  }
  CHECK(xd / wd > xc / wc + 4.0);
}

TEST_CASE("taxel noise comes from the seed") {
  TactileParams p = right();
  p.taxel.threshold_kpa = 0.0;
  TactileModel a(p, 11), b(p, 11), c(p, 12);
  float ka[34], kb[34], kc[34];
  a.taxels_rt(1.0, 0, 0, ka);
  b.taxels_rt(1.0, 0, 0, kb);
  c.taxels_rt(1.0, 0, 0, kc);
  int same = 0, differ = 0;
  for (int k = 0; k < 34; ++k) {
    same += ka[k] == kb[k] ? 1 : 0;
    differ += ka[k] != kc[k] ? 1 : 0;
  }
  CHECK(same == 34);
  CHECK(differ > 20);
}

TEST_CASE("PST: kpa_per_n x force, a held force decays through the high-pass, drift needs a tare") {
  TactileModel m(left(), 5);
  const double k = left().pst.kpa_per_n;
  double first = 0;
  for (int i = 0; i < 10; ++i) first += m.pst_rt(0, 0.5, 0.001);
  first /= 10;
  CHECK(first == doctest::Approx(0.5 * k).epsilon(0.01));
  // Held 30 s (the high-pass time constant): e^-1 of it left, within the noise.
  double last = 0;
  for (int i = 0; i < 30'000; ++i) last = m.pst_rt(0, 0.5, 0.001);
  MESSAGE("PST at 0.5 N: " << first << " kPa, after 30 s held " << last << " kPa");
  CHECK(last == doctest::Approx(0.5 * k * std::exp(-1.0)).epsilon(0.05));

  SUBCASE("noise: its standard deviation is the YAML's") {
    TactileParams p = left();
    p.pst.drift_kpa_per_s = 0;
    TactileModel n(p, 9);
    p.pst.noise_kpa = 0;
    TactileModel quiet(p, 9);
    double s = 0, s2 = 0;
    const int count = 20'000;
    for (int i = 0; i < count; ++i) {
      // 10 kPa, far from the clip at 0; the noiseless twin takes the high-pass's decay out.
      const double v = n.pst_rt(1, 1.0, 0.001) - quiet.pst_rt(1, 1.0, 0.001);
      s += v;
      s2 += v * v;
    }
    const double sd = std::sqrt(s2 / count - (s / count) * (s / count));
    MESSAGE("PST noise " << sd << " kPa");
    CHECK(sd == doctest::Approx(p.pst.noise_kpa).epsilon(0.3));  // 0.01 kPa quantisation beside 0.01 kPa noise
  }
  SUBCASE("drift: untouched, the reading creeps away from zero (what the contact controller tares)") {
    TactileParams p = left();
    p.pst.noise_kpa = 0;
    p.pst.drift_kpa_per_s = 0.01;
    TactileModel d(p, 1);
    float v = 0;
    for (int i = 0; i < 20'000; ++i) v = d.pst_rt(2, 0.0, 0.001);
    CHECK(v > 0.1f);
  }
}

TEST_CASE("the sensor models allocate nothing") {
  TactileModel r(right(), 1), l(left(), 1);
  crease::WorldHand h;
  h.tip[0].contact = 1;
  h.tip[0].normal_force_n = 1.0f;
  float taxels[5][34], pst[5];
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    for (int i = 0; i < 100; ++i) {
      r.taxels_rt(h, taxels);
      l.pst_rt(h, 0.001, pst);
    }
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(lit_taxels(taxels[0]) > 0);
  CHECK(pst[0] > 5.0f);
}
