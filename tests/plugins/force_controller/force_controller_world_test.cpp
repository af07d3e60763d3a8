// C_force against the simulated world (tests/support/hand_world.h): the left index stopped on
// the sheet by C_contact, then pressed by Eq. 6 through its PST sensor (the right index through
// its taxels, for the figure); every force scored from the world's truth (the fingertip's
// normal force), from the world's first contact. Holding 0.5 N and 2 N, a 100 mm swipe at
// 50 mm/s, a target step, bumpless switches and a hot-swap mid-hold, stale and faulty inputs,
// the hard force limit, bad goals, and no allocation in the cycles. Joints at 6 N m/rad.
#include <cmath>
#include <limits>
#include <string>

#include "support/hand_world.h"

using namespace hand_world;

namespace {

Options options(const std::string& force_params = "", robot::Side side = robot::Side::left) {
  Options o;
  o.side = side;
  o.start = side == robot::Side::left ? Vec3{-20, 40, 6} : Vec3{20, 40, 6};
  o.stiffness = 6.0;
  o.force_params = force_params;
  return o;
}

// Stopped on contact, then told to press with F over a 50 ms ramp (the sequencer's part).
void contact_then_press(HandWorld& w, double f) {
  REQUIRE(w.approach(20.0));
  w.send(HandWorld::force_goal(f, 0.05));
}

struct Hold {
  long within_ms = -1;  // from the world's first contact until the truth stays within +-10 %
  double worst = 0;     // largest |error| / f after that
};

// Runs SECONDS and scores the truth against F.
Hold hold(HandWorld& w, double f, double seconds, double band = 0.10) {
  Hold h;
  long since = -1;
  const long n = std::lround(seconds * 1000);
  std::vector<double> err;
  for (long i = 0; i < n; ++i) {
    w.cycle();
    const double e = std::fabs(w.force_n() - f) / f;
    err.push_back(e);
    if (e <= band) {
      if (since < 0) since = static_cast<long>(err.size()) - 1;
    } else {
      since = -1;
    }
  }
  if (since >= 0) {
    h.within_ms = w.cycles() - n + since - w.first_world_contact_step();
    for (std::size_t i = static_cast<std::size_t>(since); i < err.size(); ++i) h.worst = std::max(h.worst, err[i]);
  }
  return h;
}

}  // namespace

TEST_CASE("C_force holds 0.5 N and 2 N within +-10 % from at most 200 ms after the contact (failing variant: k_P = 0)") {
  for (const double f : {0.5, 2.0}) {
    CAPTURE(f);
    HandWorld w(options());
    contact_then_press(w, f);
    const Hold h = hold(w, f, 1.0);
    MESSAGE(f << " N: within 10 % from " << h.within_ms << " ms after the first contact, worst error after "
              << 100 * h.worst << " %; settled " << int(w.status().settled));
    CHECK(h.within_ms >= 0);
    CHECK(h.within_ms <= 200);
    CHECK(w.status().settled == 1);
    CHECK(w.status().mode == crease::HandMode::force);
    CHECK(w.world().max_penetration_mm() < 1.0);

    HandWorld off(options("k_p: 0"));
    contact_then_press(off, f);
    const Hold o = hold(off, f, 1.0);
    CHECK(o.within_ms < 0);
  }
}

TEST_CASE("C_force, right hand (taxels at 250 Hz): the figures") {
  for (const double f : {0.5, 2.0}) {
    CAPTURE(f);
    HandWorld w(options("", robot::Side::right));
    contact_then_press(w, f);
    const Hold h = hold(w, f, 1.0);
    MESSAGE("right hand, " << f << " N: within 10 % from " << h.within_ms << " ms after the first contact; truth "
                          << w.force_n() << " N, measured " << w.status().force_n[0] << " N");
    // 2 N: the taxels' calibration holds (tactile_model_test); 0.5 N: 0.15 N over the matrix's
    // 0.35 N threshold, and the 4 ms between samples.
    CHECK(h.within_ms >= 0);
    CHECK(h.within_ms <= 300);
  }
}

// The taxel matrices resolve a force no finer than one taxel over its 8 kPa threshold (x 11 mm^2:
// 0.09 N), so the right hand's shipped settle band is 0.1 N (config/sim.yaml, config/robot.yaml).
// Within the default 0.02 N a 0.5 N press (the swipe's) is held as well but reported settled only
// now and then: the sequence, waiting for a settled press with two fingers at once, timed out in
// a trial after 20 s at 0.52-0.57 N measured.
TEST_CASE(
    "C_force, right hand: a 0.5 N press reads settled within the taxels' resolution (failing "
    "variant: a 0.02 N band)") {
  double share[2] = {};
  for (int b = 0; b < 2; ++b) {
    const double band = b == 0 ? 0.1 : 0.02;
    CAPTURE(band);
    HandWorld w(options("settle_band_n: " + std::to_string(band), robot::Side::right));
    contact_then_press(w, 0.5);
    const Hold h = hold(w, 0.5, 0.5);  // the press reaches its force
    CHECK(h.within_ms >= 0);
    long settled = 0;
    constexpr long kCycles = 2000;
    for (long i = 0; i < kCycles; ++i) {
      w.cycle();
      settled += w.status().settled == 1 ? 1 : 0;
    }
    share[b] = static_cast<double>(settled) / kCycles;
    MESSAGE("band " << band << " N: settled in " << 100 * share[b]
                    << " % of 2 s of holding 0.5 N; truth " << w.force_n() << " N");
  }
  CHECK(share[0] > 0.9);
  CHECK(share[1] < 0.5 * share[0]);
}

// The arm's path falls 2 mm over the swipe (a sheet frame from vision off by 1.1 deg, a table
// not level): with the targets held the force follows the path's height; C_force holds it.
TEST_CASE("C_force during a 100 mm tangential swipe at 50 mm/s: within +-15 % (failing variant: the targets held)") {
  for (const double f : {0.5, 2.0}) {
    CAPTURE(f);
    for (const bool force_control : {true, false}) {
      CAPTURE(force_control);
      HandWorld w(options());
      contact_then_press(w, f);
      w.run(0.4);
      if (!force_control) {  // the variant: hold the targets it had, no force control in the swipe
        crease::HandGoal g;
        g.mode = crease::HandMode::hold;
        w.send(g);
      }
      const Vec3 from = w.here();
      w.follow(w.line(from, {from.x, from.y - 100, from.z - 2}, 0.5), 50.0, false);
      double worst = 0, sum = 0;
      int n = 0;
      for (int i = 0; i < 2000; ++i) {
        w.cycle();
        worst = std::max(worst, std::fabs(w.force_n() - f) / f);
        sum += w.force_n();
        ++n;
      }
      MESSAGE(std::string(force_control ? "force control" : "targets held") << ", " << f << " N swipe: worst error " << 100 * worst
                                                                << " %, mean " << sum / n << " N, arm moved "
                                                                << w.arm_s_mm() << " mm, friction " << w.tip().tangential_force_n << " N");
      CHECK(w.arm_s_mm() == doctest::Approx(100.02).epsilon(0.01));
      if (force_control) CHECK(worst <= 0.15);
      else CHECK(worst > 0.15);
    }
  }
}

TEST_CASE("a step of the target force settles with at most 20 % overshoot (failing variant: k_P 20 times higher)") {
  for (const double k_p : {2.0, 40.0}) {
    CAPTURE(k_p);
    HandWorld w(options("k_p: " + std::to_string(k_p) + ", max_rate_rad_s: 20"));
    contact_then_press(w, 0.5);
    w.run(0.5);
    w.send(HandWorld::force_goal(1.0, 0.0, 0, 2));
    double peak = 0;
    bool settled = false;
    for (int i = 0; i < 800; ++i) {
      w.cycle();
      peak = std::max(peak, w.force_n());
      settled = settled || w.status().settled != 0;
    }
    const double overshoot = (peak - 1.0) / 0.5;
    MESSAGE("k_P " << k_p << ": 0.5 -> 1 N step, peak " << peak << " N: overshoot " << 100 * overshoot << " % of the step");
    if (k_p < 10) {
      CHECK(overshoot <= 0.20);
      CHECK(settled);
      CHECK(w.force_n() == doctest::Approx(1.0).epsilon(0.05));
    } else {
      CHECK(overshoot > 0.20);
    }
  }
}

TEST_CASE("bumpless switches and a hot-swap mid-hold: the force within +-20 %, no commanded joint jumps over 1 mrad") {
  for (const bool carried : {true, false}) {
    CAPTURE(carried);
    HandWorld w(options());
    contact_then_press(w, 1.0);
    w.run(0.5);
    w.reset_command_jump();
    double worst = 0;
    auto score = [&](double s) {
      for (int i = 0; i < static_cast<int>(s * 1000); ++i) {
        w.cycle();
        worst = std::max(worst, std::fabs(w.force_n() - 1.0));
      }
    };
    crease::HandGoal hold_goal;
    hold_goal.mode = crease::HandMode::hold;
    w.send(hold_goal);
    score(0.2);
    w.send(HandWorld::force_goal(1.0, 0.05, 0, 3));
    score(0.2);
    if (carried) w.swap_force();
    else w.reload_force();  // the failing variant: nothing carried
    score(0.3);
    MESSAGE(std::string(carried ? "hot-swap" : "reload without state") << ": worst force error " << 100 * worst
                                                           << " %, largest commanded joint step " << w.max_command_jump_rad()
                                                           << " rad; mode after " << int(w.status().mode));
    if (carried) {
      CHECK(worst <= 0.20);
      CHECK(w.max_command_jump_rad() <= 0.001 + 1e-6);  // max_rate_rad_s x 1 ms
      CHECK(w.status().mode == crease::HandMode::force);
    } else {
      CHECK(worst > 0.20);
      CHECK(w.max_command_jump_rad() > 0.01);
    }
  }
}

TEST_CASE("stale or faulty inputs mid-press: no more force, the hand holds or retreats and says why") {
  struct Case {
    std::string name;
    std::string params;
    robot::Side side;
    crease::HandInhibit why;
  };
  for (const Case& c : {Case{"hand_state withheld, hold", "on_bad_input: hold", robot::Side::left, crease::HandInhibit::hand_state_stale},
                        Case{"hand_state withheld, retreat", "on_bad_input: retreat", robot::Side::left, crease::HandInhibit::hand_state_stale},
                        Case{"hand fault, retreat", "on_bad_input: retreat", robot::Side::left, crease::HandInhibit::hand_state_fault},
                        Case{"taxels withheld, hold", "on_bad_input: hold", robot::Side::right, crease::HandInhibit::tactile_stale}}) {
    CAPTURE(c.name);
    HandWorld w(options(c.params, c.side));
    contact_then_press(w, 2.0);
    w.run(0.5);
    const bool fault = c.why == crease::HandInhibit::hand_state_fault;
    if (c.why == crease::HandInhibit::tactile_stale) w.withhold_tactile = true;
    else if (fault) w.edit_hand = [](crease::HandState& h) { h.health = crease::DeviceHealth::fault; };
    else w.withhold_hand = true;
    // Meanwhile a goal asks for more: refused while the inputs are bad.
    w.run(0.05);
    w.send(HandWorld::force_goal(3.0, 0.0, 0, 9));
    w.run(0.5);
    MESSAGE(c.name << ": truth " << w.force_n() << " N, mode " << int(w.status().mode) << ", inhibit "
                   << int(w.status().inhibit));
    CHECK(w.status().inhibit == c.why);
    CHECK(w.status().goals_refused >= 1);
    if (std::string(c.params).find("retreat") != std::string::npos) {
      CHECK(w.status().mode == crease::HandMode::retreat);
      CHECK(w.force_n() < 0.05);  // off the sheet: safe
    } else {
      CHECK(w.status().mode == crease::HandMode::hold);
      CHECK(w.force_n() == doctest::Approx(2.0).epsilon(0.2));  // held, neither pressing on nor letting go
    }
  }
}

TEST_CASE("the hard force limit: the arm pressing on drives the fingertip over it, the hand retreats with a fault event") {
  HandWorld w(options("force_limit_n: 1.5, max_goal_force_n: 1.2"));
  contact_then_press(w, 1.0);
  w.run(0.5);
  const Vec3 from = w.here();
  w.follow(w.line(from, {from.x, from.y, from.z - 15}), 20.0, false);  // the arm goes on down
  double peak = 0;
  for (int i = 0; i < 1000; ++i) {
    w.cycle();
    peak = std::max(peak, w.force_n());
  }
  bool fault = false;
  for (const auto& e : w.force_events()) fault = fault || e.kind == crease::HandControlEvent::force_limit_fault;
  MESSAGE("force limit 1.5 N: peak " << peak << " N, at the end " << w.force_n() << " N, mode " << int(w.status().mode));
  CHECK(fault);
  CHECK(w.status().inhibit == crease::HandInhibit::force_limit);
  CHECK(w.status().mode == crease::HandMode::retreat);
  CHECK(peak < 2.0);
  // The retreat is the hand's: the arm going on down presses again (arm_motion must stop on
  // the fault event), but not past the limit within this motion.
  CHECK(w.force_n() < 1.5);
}

TEST_CASE("goals with non-finite values are refused and counted; the held hand does not move") {
  HandWorld w(options());
  contact_then_press(w, 1.0);
  w.run(0.4);
  crease::HandGoal hold_goal;
  hold_goal.mode = crease::HandMode::hold;
  w.send(hold_goal);
  w.run(0.01);
  const HandQ before = w.commanded_targets();
  crease::HandGoal bad = HandWorld::force_goal(std::numeric_limits<float>::quiet_NaN(), 0.0);
  w.send(bad);
  crease::HandGoal posture;
  posture.mode = crease::HandMode::posture;
  posture.target_rad[3] = std::numeric_limits<float>::infinity();
  w.send(posture);
  w.run(0.2);
  CHECK(w.status().goals_refused == 2);
  CHECK(w.status().last_refusal == static_cast<std::uint8_t>(crease::GoalRefusal::non_finite));
  CHECK(w.status().mode == crease::HandMode::hold);
  for (int j = 0; j < robot::kHandJoints; ++j) CHECK(w.commanded_targets()[j] == before[j]);
  CHECK(w.force_n() == doctest::Approx(1.0).epsilon(0.1));
}

TEST_CASE("the control cycles (both controllers) allocate nothing in steady state, pressing and swiping") {
  HandWorld w(options());
  contact_then_press(w, 0.5);
  w.run(0.3);
  const auto before = crease::rt::rt_allocation_count();
  w.run(0.5);
  const Vec3 from = w.here();
  const ArmPath swipe = w.line(from, {from.x, from.y - 30, from.z}, 0.5);  // IK outside the counted cycles
  const auto mid = crease::rt::rt_allocation_count();
  w.follow(swipe, 50.0, false);
  w.run(0.6);
  CHECK(mid == before);
  CHECK(crease::rt::rt_allocation_count() == mid);
}
