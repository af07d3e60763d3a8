#include "support/hand_world.h"

using namespace hand_world;

TEST_CASE("explore") {
  for (double kp : {0.5, 1.0, 2.0, 4.0}) for (double f : {0.5, 2.0}) {
    Options o;
    o.stiffness = 6.0;
    o.contact_params = "tactile_enter_kpa: 0.03, tactile_exit_kpa: 0.015, enter_rad: 0.001, exit_rad: 0.0005";
    o.force_params = "k_p: " + std::to_string(kp);
    HandWorld w(o);
    REQUIRE(w.approach(20.0));
    const long c0 = w.first_contact_cycle();
    w.send(HandWorld::force_goal(f, 0.05));
    long in_since = -1; double peak = 0;
    for (int i = 0; i < 600; ++i) {
      w.cycle();
      const double e = std::fabs(w.force_n() - f) / f;
      if (e <= 0.1) { if (in_since < 0) in_since = w.cycles(); } else in_since = -1;
      peak = std::max(peak, w.force_n());
      if (i % 50 == 0 && kp == 1.0) MESSAGE("  t " << i << " truth " << w.force_n() << " meas " << w.status().force_n[0] << " tgt " << w.status().force_target_n << " mode " << int(w.status().mode) << " FFJ3 " << w.command().target_rad[3] << " sat " << int(w.status().saturated));
    }
    MESSAGE("kp " << kp << " f " << f << " within 10% from " << (in_since - c0) << " ms after contact, peak " << peak << " settled " << int(w.status().settled));
  }
}
