#include "support/hand_world.h"

using namespace hand_world;

TEST_CASE("explore") {
  for (int side = 0; side < 2; ++side) {
    Options o;
    o.side = side == 0 ? robot::Side::left : robot::Side::right;
    if (side == 1) o.start = {20, 40, 6};
    o.with_force = false;
    o.stiffness = 6.0;
    o.contact_params = "tactile_enter_kpa: 0.03, tactile_exit_kpa: 0.015, enter_rad: 0.001, exit_rad: 0.0005";
    HandWorld w(o);
    w.observer_ = [&] {
      if (w.first_world_contact_step() >= 0 && w.cycles() < w.first_world_contact_step() + 40)
        MESSAGE("k " << w.cycles() - 1 << " force " << w.force_n() << " dev " << w.contact().deviation_rad << " in " << int(w.contact().in_contact));
    };
    const bool hit = w.approach(20.0);
    MESSAGE("side " << side << " hit " << hit << " world contact step " << w.first_world_contact_step() << " detected "
                    << w.first_contact_cycle() << " source " << int(w.contact().source) << " dev " << w.contact().deviation_rad
                    << " force " << w.force_n());
    w.observer_ = nullptr;
    w.run(0.3);
    MESSAGE("after stop: force " << w.force_n() << " pen " << w.world().max_penetration_mm() << " travel past contact "
                                 << w.arm_s_mm() << " stopped " << w.stopped_cycle());
  }
}
