// C_contact against the simulated world (tests/support/hand_world.h): an index fingertip moved
// down onto the sheet at 20 mm/s by the arm is stopped on the contact the controller reports,
// scored from the world's truth: how many cycles after the world's first contact it was
// detected, how deep the fingertip went into the sheet, the contact force at the stop. The
// debounce shown to matter (off, the sensors' noise alone makes contacts), and 60 s of free
// motion without a false contact. The hands' joints at 6 N m/rad during the approach (seed
// 000: "the controllable joint stiffness and the employed threshold ... select an appropriate
// contact force"); the controllers' defaults otherwise.
#include <string>

#include "support/hand_world.h"

using namespace hand_world;

namespace {

Options approach_options(robot::Side side, const std::string& contact_params = "") {
  Options o;
  o.side = side;
  o.start = side == robot::Side::left ? Vec3{-20, 40, 6} : Vec3{20, 40, 6};
  o.stiffness = 6.0;
  o.with_force = false;
  o.contact_params = contact_params;
  return o;
}

struct Stop {
  long latency_cycles = -1;  // detection cycle - the world's first contact step
  double force_at_stop_n = 0, force_after_n = 0;
  double penetration_mm = 0;  // worst, over 0.3 s after the stop
  double travel_mm = 0;       // of the arm's path past the first contact
};

Stop approach_and_stop(const Options& o) {
  HandWorld w(o);
  const bool hit = w.approach(20.0);
  Stop s;
  if (!hit) return s;
  s.latency_cycles = w.first_contact_cycle() - w.first_world_contact_step();
  s.force_at_stop_n = w.force_n();
  for (int i = 0; i < 300; ++i) {
    w.cycle();
    s.penetration_mm = std::max(s.penetration_mm, w.world().max_penetration_mm());
  }
  s.force_after_n = w.force_n();
  s.travel_mm = w.travel_since_contact_mm();
  return s;
}

void print(const char* tag, const Stop& s) {
  MESSAGE(std::string(tag) << ": detected " << s.latency_cycles << " cycles after the world's first contact; force at the stop "
              << s.force_at_stop_n << " N, 0.3 s later " << s.force_after_n << " N; arm travel past the contact "
              << s.travel_mm << " mm; worst depth in the sheet " << s.penetration_mm << " mm");
}

}  // namespace

TEST_CASE("C_contact, left hand (PST OR joints): stopped within 3 cycles of the first contact, <= 1 mm deep") {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {  // three draws of the sensors' noise
    CAPTURE(seed);
    Options o = approach_options(robot::Side::left);
    o.sensor_seed = seed;
    const Stop s = approach_and_stop(o);
    print("left hand", s);
    CHECK(s.latency_cycles >= 1);  // the world's state reaches the controller one cycle later
    CHECK(s.latency_cycles <= 3);
    CHECK(s.penetration_mm <= 1.0);
    // The stated band of the contact force at the stop: from a few mN when it is detected to
    // under 0.1 N once the arm has stopped (it decelerates at 1 m/s^2 from 20 mm/s: 0.2 mm
    // further at about 0.2 N/mm).
    CHECK(s.force_at_stop_n > 0.003);
    CHECK(s.force_after_n < 0.1);
  }

  SUBCASE("failing variant: without the tactile OR, the joints alone detect it later") {
    const Stop j = approach_and_stop(approach_options(robot::Side::left, "tactile: none"));
    print("left hand, joints only", j);
    CHECK(j.latency_cycles > 3);
  }
}

TEST_CASE("C_contact, right hand (joints; the taxels see nothing below 0.35 N): the figure") {
  const Stop s = approach_and_stop(approach_options(robot::Side::right));
  print("right hand", s);
  // Measured 19 cycles (2026-12): Eq. 5's 2 mrad are reached after 0.4 mm of compression. The
  // issue's 3 cycles are not reached by the joints alone (not loosened: a figure, stated).
  CHECK(s.latency_cycles > 3);
  CHECK(s.latency_cycles <= 25);
  CHECK(s.penetration_mm <= 1.0);
  CHECK(s.force_after_n < 0.15);
}

namespace {

// The arm moves the hand to and fro 60 mm sideways at 20 mm/s, 10 mm over the sheet, for
// SECONDS; returns the contact onsets the controller reported.
std::uint64_t free_motion(const std::string& contact_params, double seconds) {
  Options o = approach_options(robot::Side::left, contact_params);
  o.start = {-20, 40, 16};
  HandWorld w(o);
  REQUIRE(w.run_until([&] { return w.contact().armed != 0; }, 1.0));
  const ArmPath out = w.line(o.start, {o.start.x - 60, o.start.y, o.start.z}, 0.5);
  const ArmPath back = w.line({o.start.x - 60, o.start.y, o.start.z}, o.start, 0.5);
  int touching = 0;
  w.observer_ = [&] { touching += w.tip().contact != 0 ? 1 : 0; };
  const int legs = static_cast<int>(seconds / 3.0);
  for (int i = 0; i < legs; ++i) {
    w.follow(i % 2 == 0 ? out : back, 20.0, false);
    w.run(3.0);
  }
  CHECK(touching == 0);  // the truth: nothing was touched
  CHECK(w.contact().armed == 1);
  CHECK(w.contact().healthy == 1);
  return w.contact().onsets;
}

}  // namespace

TEST_CASE("free motion: no false contact in 60 s; with the debounce off, sensor noise alone makes contacts") {
  const std::uint64_t debounced = free_motion("", 60.0);
  const std::uint64_t raw = free_motion("debounce_cycles: 1", 60.0);
  MESSAGE("false contacts in free motion: " << debounced << " in 60 s debounced (2 cycles), " << raw
                                            << " in 60 s without a debounce");
  CHECK(debounced == 0);
  CHECK(raw > 0);
}

TEST_CASE("a hot-swap of the contact controller in contact keeps the contact (failing variant: reloaded, it must settle anew)") {
  for (const bool carried : {true, false}) {
    CAPTURE(carried);
    HandWorld w(approach_options(robot::Side::left));
    REQUIRE(w.approach(20.0));
    w.run(0.2);
    REQUIRE(w.contact().onsets == 1);
    if (carried) w.swap_contact();
    else w.reload_contact();
    w.run(0.2);
    if (carried) {
      CHECK(w.contact().in_contact == 1);
      CHECK(w.contact().armed == 1);
      CHECK(w.contact().onsets == 1);  // no second onset: the same contact
    } else {
      CHECK(w.contact().onsets == 0);     // a new count
      CHECK(w.contact().in_contact == 0);  // and the touching hand, re-armed, taken as relaxed
      CHECK(w.tip().contact == 1);
    }
  }
}
