// The hand's command stage on a synthetic hand: a first finger pressing a spring (18 N per rad
// of FFJ3 + 0.4 FFJ2 past the contact, about the simulated index's figure at 6 N m/rad), its
// PST sensor 10 kPa/N over a 0.3 kPa offset. Eq. 6 reaches and holds the target, alpha shapes
// the flexion, the target ramps, every commanded joint is rate limited, saturation with
// anti-windup, bumpless mode switches, refused goals, stale and faulty inputs, the hard force
// limit, the state a hot-swap carries, the high-pass undone, the parameters checked. Each
// beside its failing variant.
#include "plugins/force_controller/hand_controller.h"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "plugins/force_controller/force_params.h"
#include "rt/alloc_guard.h"

using namespace crease;
using namespace crease::force;

namespace {

constexpr int FFJ3 = 3, FFJ2 = 4, MFJ3 = 6, THJ2 = 18, WRJ1 = 1;

std::string robot_yaml() { return std::string(CREASE_SOURCE_DIR) + "/config/robot/crease_robot.yaml"; }

ForceConfig config(const std::string& extra = "", const std::string& side = "left") {
  std::string y = "{side: " + side + ", robot: " + robot_yaml() + ", undo_highpass: false";
  if (!extra.empty()) y += ", " + extra;
  if (extra.find("start: ") == std::string::npos) y += ", start: hold";  // held from the first state
  y += "}";
  return read_force_config(Params(YAML::Load(y), "f.yaml", "force.params"));
}

struct Rig {
  explicit Rig(const ForceConfig& c) : hc(c) {
    hand.health = DeviceHealth::ok;
    hand.fresh = 1;
    hand.pressure_valid = 0x1F;
    for (int j = 0; j < kJoints; ++j) hand.position_rad[j] = 0.1f;  // the hand's pose at start
    contact.healthy = 1;
    tactile.health = DeviceHealth::ok;
    tactile.valid = 0x1F;
    sense();
  }
  // The spring: force of the first finger from its commanded flexion past the contact.
  [[nodiscard]] double plant_force() const {
    if (!commanded) return 0;
    return std::max(0.0, k_plant * ((cmd.target_rad[FFJ3] - 0.1) + 0.4 * (cmd.target_rad[FFJ2] - 0.1) + 0.001));
  }
  void sense() {
    const double f = plant_force();
    for (int k = 0; k < 5; ++k) hand.pressure_kpa[k] = 0.3f;
    hand.pressure_kpa[0] = static_cast<float>(0.3 + 10.0 * f);
    contact.fingers = f > 0 ? 1 : 0;
    contact.in_contact = contact.fingers;
    contact.timestamp_ns = t;
    for (float& p : tactile.pressure_kpa[0]) p = 0;
    tactile.pressure_kpa[0][0] = static_cast<float>(f * 1000.0 / 11.0);  // one taxel, area 11 mm^2
    tactile.timestamp_ns = tactile_streaming ? t : tactile.timestamp_ns;
  }
  ForceInputs inputs(bool fresh = true) {
    ForceInputs in;
    in.time_ns = t;
    in.hand = &hand;
    in.hand_new = fresh;
    in.contact = &contact;
    in.tactile = &tactile;
    return in;
  }
  bool submit(const HandGoal& g) { return hc.submit_rt(g, inputs()); }
  void step(bool fresh = true) {
    const HandCommand before = cmd;
    commanded = hc.step_rt(inputs(fresh), cmd, st) || commanded;
    if (had_command)
      for (int j = 0; j < kJoints; ++j) max_step = std::max(max_step, std::fabs(cmd.target_rad[j] - before.target_rad[j]));
    had_command = commanded;
    hc.clear_events();
    t += 1'000'000;
    sense();
  }
  void steps(int n, bool fresh = true) {
    for (int i = 0; i < n; ++i) step(fresh);
  }
  static HandGoal force(double f, double ramp = 0.0, std::uint8_t fingers = 1) {
    HandGoal g;
    g.mode = HandMode::force;
    g.force_n = static_cast<float>(f);
    g.ramp_s = static_cast<float>(ramp);
    g.fingers = fingers;
    return g;
  }
  static HandGoal hold() {
    HandGoal g;
    g.mode = HandMode::hold;
    return g;
  }
  HandController hc;
  HandState hand;
  ContactState contact;
  Tactile tactile;
  HandCommand cmd;
  HandControlStatus st;
  double k_plant = 18.0;
  bool commanded = false, had_command = false, tactile_streaming = true;
  float max_step = 0;
  std::int64_t t = 1'000'000'000;
};

}  // namespace

TEST_CASE("before any hand_state nothing is commanded; the first holds the hand where it is") {
  Rig r(config());
  ForceInputs none;
  none.time_ns = r.t;
  HandCommand c;
  HandControlStatus s;
  CHECK_FALSE(r.hc.step_rt(none, c, s));
  CHECK(s.commanding == 0);
  r.step();
  CHECK(r.commanded);
  CHECK(r.cmd.enable == 1);
  for (int j = 0; j < kJoints; ++j) CHECK(r.cmd.target_rad[j] == 0.1f);
  CHECK(r.cmd.stiffness_nm_per_rad[0] == 2.0f);
  CHECK(r.st.mode == HandMode::hold);
}

TEST_CASE("start: limp (the default): enable 0 following the hand until a goal, then taken over where it lies (failing variant: start: hold)") {
  for (const bool limp : {true, false}) {
    CAPTURE(limp);
    Rig r(config(limp ? "start: limp" : "start: hold"));
    r.steps(5);
    REQUIRE(r.commanded);
    CHECK(r.st.commanding == 1);
    if (!limp) {  // the failing variant: held stiff from the first state
      CHECK(r.cmd.enable == 1);
      CHECK(r.cmd.stiffness_nm_per_rad[FFJ3] == 2.0f);
      CHECK(r.st.limp == 0);
      continue;
    }
    CHECK(r.cmd.enable == 0);
    CHECK(r.st.limp == 1);
    for (int j = 0; j < kJoints; ++j) CHECK(r.cmd.stiffness_nm_per_rad[j] == 0.0f);
    // The limp hand sags: the targets follow it, nothing resists.
    for (int i = 0; i < 20; ++i) {
      r.hand.position_rad[FFJ3] += 0.005f;
      r.step();
    }
    CHECK(r.cmd.enable == 0);
    CHECK(r.cmd.target_rad[FFJ3] == r.hand.position_rad[FFJ3]);
    // A bad input meanwhile: it stays limp (nothing retreats), goals refused while it lasts.
    r.hand.health = DeviceHealth::fault;
    r.steps(3);
    CHECK(r.cmd.enable == 0);
    CHECK(r.st.inhibit == HandInhibit::hand_state_fault);
    CHECK_FALSE(r.submit(Rig::hold()));
    r.hand.health = DeviceHealth::ok;
    r.steps(5);
    // A hold goal: enabled at default_stiffness where the hand is now, no jump.
    const float here = r.hand.position_rad[FFJ3];
    REQUIRE(r.submit(Rig::hold()));
    r.max_step = 0;
    r.steps(50);
    CHECK(r.cmd.enable == 1);
    CHECK(r.st.limp == 0);
    CHECK(r.cmd.stiffness_nm_per_rad[FFJ3] == 2.0f);
    CHECK(r.cmd.target_rad[FFJ3] == here);
    CHECK(r.max_step == 0.0f);
  }
}

TEST_CASE("joint_stiffness holds the named joints at their own stiffness from the first state, the rest at default_stiffness") {
  Rig r(config("start: hold, default_stiffness: 1.5, joint_stiffness: {WRJ2: 30, WRJ1: 25}"));
  r.steps(5);
  REQUIRE(r.cmd.enable == 1);
  CHECK(r.cmd.stiffness_nm_per_rad[0] == 30.0f);  // WRJ2 (drivers/README.md §3)
  CHECK(r.cmd.stiffness_nm_per_rad[1] == 25.0f);  // WRJ1
  for (int j = 2; j < kJoints; ++j) CHECK(r.cmd.stiffness_nm_per_rad[j] == 1.5f);
  // Without it every joint at default_stiffness.
  Rig plain(config("start: hold, default_stiffness: 1.5"));
  plain.steps(5);
  for (int j = 0; j < kJoints; ++j) CHECK(plain.cmd.stiffness_nm_per_rad[j] == 1.5f);
}

TEST_CASE("Eq. 6 presses the finger to 0.5 N and 2 N and holds it; settled is reported (failing variant: k_P = 0)") {
  for (const double k_p : {2.0, 0.0}) {
    for (const double target : {0.5, 2.0}) {
      CAPTURE(k_p);
      CAPTURE(target);
      Rig r(config("k_p: " + std::to_string(k_p)));
      r.step();
      REQUIRE(r.submit(Rig::force(target, 0.05)));
      int within_at = -1;
      for (int i = 0; i < 600; ++i) {
        r.step();
        const bool in = std::fabs(r.plant_force() - target) <= 0.1 * target;
        if (in && within_at < 0) within_at = i;
        if (!in) within_at = -1;
      }
      if (k_p > 0) {
        MESSAGE("within 10 % of " << target << " N after " << within_at << " cycles");
        CHECK(within_at >= 0);
        CHECK(within_at < 200);
        CHECK(r.st.settled == 1);
        CHECK(r.st.force_n[0] == doctest::Approx(target).epsilon(0.02));
      } else {
        CHECK(within_at < 0);
        CHECK(r.st.settled == 0);
      }
      CHECK(r.st.mode == HandMode::force);
      CHECK(r.st.fingers == 1);
    }
  }
}

TEST_CASE("alpha: the proximal joint flexes more than the distal; the thumb and the other fingers never move") {
  Rig r(config("alpha: {FFJ3: 1.0, FFJ2: 0.4, MFJ3: 1.0, MFJ2: 0.4}"));
  r.step();
  REQUIRE(r.submit(Rig::force(1.0, 0.0)));
  r.steps(300);
  const double d3 = r.cmd.target_rad[FFJ3] - 0.1, d2 = r.cmd.target_rad[FFJ2] - 0.1;
  CHECK(d3 > 0.02);
  CHECK(d2 / d3 == doctest::Approx(0.4).epsilon(1e-3));
  CHECK(r.cmd.target_rad[MFJ3] == 0.1f);  // not among `fingers`
  CHECK(r.cmd.target_rad[THJ2] == 0.1f);
  CHECK(r.cmd.target_rad[WRJ1] == 0.1f);
}

TEST_CASE("the target force ramps from what was measured (failing variant: no ramp, a step)") {
  for (const double ramp : {0.1, 0.0}) {
    CAPTURE(ramp);
    Rig r(config());
    r.step();
    REQUIRE(r.submit(Rig::force(1.0, ramp)));
    r.steps(50);
    if (ramp > 0) CHECK(r.st.force_target_n == doctest::Approx(0.5).epsilon(0.05));
    else CHECK(r.st.force_target_n == 1.0f);
  }
}

TEST_CASE("every commanded joint is rate limited (failing variant: a rate limit 20 times higher)") {
  for (const double rate : {1.0, 20.0}) {
    CAPTURE(rate);
    Rig r(config("k_p: 100, max_rate_rad_s: " + std::to_string(rate)));
    r.step();
    REQUIRE(r.submit(Rig::force(2.0)));
    r.steps(100);
    if (rate < 2) CHECK(r.max_step <= 0.001f + 1e-6f);
    else CHECK(r.max_step > 0.005f);
  }
}

TEST_CASE("saturation with anti-windup: after an unreachable target the force follows a low one at once (failing variant: anti_windup false)") {
  int recover[2] = {-1, -1};
  for (const bool aw : {true, false}) {
    Rig r(config(std::string("max_flex_rad: 0.02, anti_windup: ") + (aw ? "true" : "false")));
    r.step();
    REQUIRE(r.submit(Rig::force(3.0)));  // 0.02 rad of flexion gives 0.5 N: unreachable
    r.steps(1000);
    CHECK(r.st.saturated == 1);
    CHECK(r.cmd.target_rad[FFJ3] == doctest::Approx(0.12).epsilon(1e-4));  // at the bound
    REQUIRE(r.submit(Rig::force(0.2)));
    for (int i = 0; i < 3000; ++i) {
      r.step();
      if (r.plant_force() < 0.22) {
        recover[aw ? 0 : 1] = i;
        break;
      }
    }
  }
  MESSAGE("cycles to follow the low target: anti-windup " << recover[0] << ", without " << recover[1]);
  CHECK(recover[0] >= 0);
  CHECK(recover[0] < 100);
  CHECK((recover[1] < 0 || recover[1] > 500));
}

TEST_CASE("bumpless: posture, hold and force switch at a cycle boundary without a jump in the targets") {
  Rig r(config());
  r.step();
  REQUIRE(r.submit(Rig::force(1.0, 0.05)));
  r.steps(300);
  const float before_hold = r.cmd.target_rad[FFJ3];
  REQUIRE(r.submit(Rig::hold()));
  r.step();
  CHECK(r.cmd.target_rad[FFJ3] == before_hold);
  r.steps(100);
  CHECK(r.plant_force() == doctest::Approx(1.0).epsilon(0.05));
  REQUIRE(r.submit(Rig::force(1.0, 0.05)));  // back to force: the ramp starts at what is measured
  r.step();
  CHECK(std::fabs(r.cmd.target_rad[FFJ3] - before_hold) < 1e-4f);
  r.steps(100);
  HandGoal posture;  // the middle finger far away, at once: the rate limit walks it there
  posture.mode = HandMode::posture;
  for (int j = 0; j < kJoints; ++j) posture.target_rad[j] = r.cmd.target_rad[j];
  posture.target_rad[MFJ3] = 0.5f;
  REQUIRE(r.submit(posture));
  r.steps(500);
  CHECK(r.cmd.target_rad[MFJ3] == doctest::Approx(0.5f));
  REQUIRE(r.submit(Rig::force(0.5, 0.05)));
  r.steps(300);
  MESSAGE("largest commanded joint step over every switch: " << r.max_step << " rad");
  CHECK(r.max_step <= 0.001f + 1e-6f);  // max_rate_rad_s x dt
}

TEST_CASE("goals with bad values are refused and counted; nothing moves") {
  Rig r(config());
  r.step();
  const HandCommand before = r.cmd;
  HandGoal nan = Rig::force(std::numeric_limits<float>::quiet_NaN());
  HandGoal inf_target;
  inf_target.mode = HandMode::posture;
  inf_target.target_rad[5] = std::numeric_limits<float>::infinity();
  HandGoal retreat_goal;
  retreat_goal.mode = HandMode::retreat;
  HandGoal unknown;
  unknown.mode = static_cast<HandMode>(9);
  HandGoal no_fingers = Rig::force(0.5, 0.0, 0);
  r.contact.fingers = 0;
  CHECK_FALSE(r.submit(nan));
  CHECK(r.hc.state().last_refusal == GoalRefusal::non_finite);
  CHECK_FALSE(r.submit(inf_target));
  CHECK_FALSE(r.submit(retreat_goal));
  CHECK(r.hc.state().last_refusal == GoalRefusal::bad_mode);
  CHECK_FALSE(r.submit(unknown));
  CHECK_FALSE(r.submit(Rig::force(-1.0)));
  CHECK(r.hc.state().last_refusal == GoalRefusal::out_of_range);
  CHECK_FALSE(r.submit(Rig::force(4.5)));  // above max_goal_force_n
  CHECK_FALSE(r.submit(Rig::force(0.5, -1.0)));
  CHECK_FALSE(r.submit(no_fingers));
  CHECK(r.hc.state().last_refusal == GoalRefusal::no_fingers);
  CHECK(r.hc.events().size() == HandController::kMaxEvents);  // the first four, the rest counted lost
  r.steps(100);
  CHECK(r.st.goals_refused == 8);
  CHECK(r.st.goals_accepted == 0);
  CHECK(r.st.mode == HandMode::hold);
  for (int j = 0; j < kJoints; ++j) CHECK(r.cmd.target_rad[j] == before.target_rad[j]);
}

TEST_CASE("stale hand_state: force stops being added, the hand holds or retreats, goals are refused") {
  for (const std::string policy : {"hold", "retreat"}) {
    CAPTURE(policy);
    Rig r(config("on_bad_input: " + policy + ", stale_cycles: 3, retreat_rad: 0.1"));
    r.step();
    REQUIRE(r.submit(Rig::force(1.0, 0.05)));
    r.steps(300);
    const float pressed = r.cmd.target_rad[FFJ3];
    r.k_plant = 9.0;  // what the stale status no longer shows: the force drops, Eq. 6 would flex on
    r.steps(3, false);
    CHECK(r.st.inhibit == HandInhibit::none);  // within the bound
    r.steps(300, false);
    CHECK(r.st.inhibit == HandInhibit::hand_state_stale);
    CHECK(r.st.inhibits == 1);
    if (policy == "hold") {
      CHECK(r.st.mode == HandMode::hold);
      CHECK(std::fabs(r.cmd.target_rad[FFJ3] - pressed) < 0.0031f);  // at most the 3 tolerated cycles
    } else {
      CHECK(r.st.mode == HandMode::retreat);
      CHECK(r.cmd.target_rad[FFJ3] == doctest::Approx(0.1 - 0.1).epsilon(1e-4));  // the force start - retreat_rad
      CHECK(r.plant_force() == 0.0);
    }
    CHECK_FALSE(r.submit(Rig::force(1.0)));
    CHECK(r.hc.state().last_refusal == GoalRefusal::inputs_bad);
    // Fresh again: it stays where it is until a new goal (no stale plan resumes).
    const float now = r.cmd.target_rad[FFJ3];
    r.steps(100);
    CHECK(r.cmd.target_rad[FFJ3] == now);
    CHECK(r.submit(Rig::force(1.0, 0.05)));
    r.steps(300);
    CHECK(r.plant_force() == doctest::Approx(1.0).epsilon(0.05));
    CHECK(r.st.inhibit == HandInhibit::none);
  }
}

TEST_CASE("hand_state health fault: at once; degraded counts as not fresh") {
  Rig r(config("stale_cycles: 3"));
  r.step();
  REQUIRE(r.submit(Rig::force(1.0, 0.05)));
  r.steps(100);
  r.hand.health = DeviceHealth::fault;
  r.step();
  CHECK(r.st.inhibit == HandInhibit::hand_state_fault);
  CHECK(r.st.mode == HandMode::hold);
  Rig d(config("stale_cycles: 3"));
  d.step();
  d.hand.health = DeviceHealth::degraded;
  d.steps(4);
  CHECK(d.st.inhibit == HandInhibit::hand_state_stale);
}

TEST_CASE("the right hand: the force is the taxel sum x the calibrated area; a silent or faulty matrix inhibits") {
  Rig r(config("max_tactile_age_ms: 20", "right"));
  r.step();
  REQUIRE(r.submit(Rig::force(2.0, 0.05)));
  r.steps(400);
  CHECK(r.plant_force() == doctest::Approx(2.0).epsilon(0.02));
  CHECK(r.st.force_n[0] == doctest::Approx(2.0).epsilon(0.02));
  SUBCASE("silent") {
    r.tactile_streaming = false;
    r.steps(20);
    CHECK(r.st.inhibit == HandInhibit::none);
    r.steps(2);
    CHECK(r.st.inhibit == HandInhibit::tactile_stale);
  }
  SUBCASE("fault") {
    r.tactile.health = DeviceHealth::fault;
    r.step();
    CHECK(r.st.inhibit == HandInhibit::tactile_fault);
  }
  CHECK(r.st.mode == HandMode::hold);
}

TEST_CASE("the hard force limit: exceeded, the hand retreats and a fault event is raised, whatever the target") {
  Rig r(config("force_limit_n: 2.5, max_goal_force_n: 2.4, retreat_rad: 0.1"));
  r.step();
  REQUIRE(r.submit(Rig::force(2.0, 0.05)));
  r.steps(300);
  r.k_plant = 40.0;  // the surface stiffens (the arm pressed on): 4.4 N at once
  HandCommand c;
  HandControlStatus s;
  r.sense();
  bool fault_event = false;
  for (int k = 1; k <= 3; ++k) {  // force_limit_samples: 3 samples over it in a row
    CAPTURE(k);
    r.hc.clear_events();
    (void)r.hc.step_rt(r.inputs(), c, s);
    for (const auto& e : r.hc.events())
      fault_event = fault_event || (e.kind == HandControlEvent::force_limit_fault &&
                                    e.finger == 0 && e.value > 2.5f);
    CHECK(fault_event == (k == 3));
  }
  CHECK(fault_event);
  CHECK(s.inhibit == HandInhibit::force_limit);
  CHECK(s.mode == HandMode::retreat);
  r.cmd = c;
  r.hc.clear_events();
  r.steps(300);
  CHECK(r.plant_force() == 0.0);
  CHECK(r.st.mode == HandMode::retreat);
  CHECK(r.st.inhibits == 1);
  CHECK(r.submit(Rig::force(1.0, 0.05)));  // under the limit again: a new goal is taken
}

// The world's contacts spike for a step (a trial: 7.1 N for one step on a finger pressing 2 N);
// one or two samples over the limit are no overload. Failing variant: force_limit_samples 1.
TEST_CASE(
    "the force limit takes force_limit_samples samples over it in a row: a spike of fewer is no "
    "overload") {
  for (const int samples : {3, 1}) {
    CAPTURE(samples);
    Rig r(config("force_limit_n: 2.5, max_goal_force_n: 2.4, force_limit_samples: " +
                 std::to_string(samples)));
    r.step();
    REQUIRE(r.submit(Rig::force(2.0, 0.05)));
    r.steps(300);
    for (int spike = 0; spike < 2; ++spike) {  // two samples at 7 N, then the press as it was
      r.step();
      r.hand.pressure_kpa[0] = static_cast<float>(0.3 + 10.0 * 7.0);
    }
    r.steps(50);
    CHECK(r.st.inhibits == (samples == 1 ? 1u : 0u));
    CHECK((r.st.mode == HandMode::retreat) == (samples == 1));
    if (samples == 3) CHECK(r.plant_force() == doctest::Approx(2.0).epsilon(0.05));
  }
}

TEST_CASE("hot-swap state: a controller restored from the state goes on bit for bit (failing variant: a fresh one lets go)") {
  Rig a(config());
  a.step();
  REQUIRE(a.submit(Rig::force(1.0, 0.05)));
  a.steps(300);
  Rig b(config());
  b.hand = a.hand;
  b.t = a.t;
  b.hc.restore(a.hc.state());
  b.commanded = true;
  a.step();
  b.step();
  for (int j = 0; j < kJoints; ++j) CHECK(b.cmd.target_rad[j] == a.cmd.target_rad[j]);
  CHECK(b.st.mode == HandMode::force);
  Rig fresh(config());
  fresh.hand = a.hand;
  fresh.hand.position_rad[FFJ3] = 0.1f;  // a compliant finger in contact sits short of its target
  fresh.step();
  CHECK(fresh.st.mode == HandMode::hold);
  CHECK(std::fabs(fresh.cmd.target_rad[FFJ3] - a.cmd.target_rad[FFJ3]) > 0.04f);
}

TEST_CASE("the PST's high-pass undone: a long hold keeps the true force (failing variant: undo_highpass false)") {
  double creep[2] = {0, 0};
  for (const bool undo : {true, false}) {
    ForceConfig c = config();
    c.pst_highpass_s = undo ? 30.0 : 0.0;
    Rig r(c);
    r.step();
    REQUIRE(r.submit(Rig::force(1.0, 0.05)));
    double hp_base = 0;  // the sensor's own high-pass of its cavity pressure
    for (int i = 0; i < 10'000; ++i) {
      r.step();
      const double raw = 10.0 * r.plant_force();
      hp_base += (raw - hp_base) * 0.001 / 30.0;
      r.hand.pressure_kpa[0] = static_cast<float>(0.3 + raw - hp_base);
    }
    creep[undo ? 0 : 1] = r.plant_force() - 1.0;
  }
  MESSAGE("true force after 10 s held at 1 N: " << 1 + creep[0] << " N with the high-pass undone, " << 1 + creep[1] << " N without");
  CHECK(std::fabs(creep[0]) < 0.02);
  CHECK(creep[1] > 0.3);
}

// After a long press the PST's high-pass has taken most of the held pressure away; released, its
// output undershoots by that (clipped at the wire's 0) and recovers with the time constant, so
// the next press reads low by what is left. The controller keeps its estimate of the high-pass
// through the release. Failing variant (the estimate forgotten on release, as before): the second
// press holds the sensor's reading at 1 N, the finger ~1.5 N.
TEST_CASE(
    "the PST's high-pass kept through a release: a press after a long one holds the true force") {
  ForceConfig c = config();
  c.pst_highpass_s = 30.0;
  Rig r(c);
  r.step();
  double hp_base = 0;  // the sensor's own high-pass of its cavity pressure
  auto sensor = [&] {
    const double raw = 10.0 * r.plant_force();
    hp_base += (raw - hp_base) * 0.001 / 30.0;
    r.hand.pressure_kpa[0] =
        static_cast<float>(std::max(0.0, std::round((0.3 + raw - hp_base) * 100.0) / 100.0));
  };
  auto run = [&](int n) {
    for (int i = 0; i < n; ++i) {
      r.step();
      sensor();
    }
  };
  REQUIRE(r.submit(Rig::force(1.0, 0.05)));
  run(30'000);
  const double first = r.plant_force();
  HandGoal open;  // the finger off: back to where it was before the press
  open.mode = HandMode::posture;
  for (int j = 0; j < kJoints; ++j) open.target_rad[j] = 0.09f;
  REQUIRE(r.submit(open));
  run(3000);
  REQUIRE(r.plant_force() == 0.0);
  CHECK(r.hand.pressure_kpa[0] == 0.0f);  // the undershoot, clipped
  CHECK(r.st.force_n[0] == 0.0f);
  REQUIRE(r.submit(Rig::force(1.0, 0.05)));
  run(3000);
  MESSAGE("true force at the end of a 30 s press at 1 N: "
          << first << " N; 3 s after the release, the next press: " << r.plant_force()
          << " N (the sensor's high-pass then " << hp_base / 10.0 << " N)");
  CHECK(first == doctest::Approx(1.0).epsilon(0.03));
  CHECK(hp_base > 4.0);  // the sensor did lose most of the first press
  CHECK(r.plant_force() == doctest::Approx(1.0).epsilon(0.05));
}

// hand_state's pressure_valid is per cycle: a cycle whose pressure frame did not come in (a late
// device, a loaded machine) has none. The force is then held as last measured, not read as 0 N:
// a press on a link that drops every third sample stays at its goal and settles. Failing
// variant (a missing sample read as 0 N, as before): the force loop pushes on every gap and the
// settling restarts, so it never settles.
TEST_CASE("a cycle without a PST sample holds the force as last measured: the press settles with samples missing") {
  Rig r(config());
  r.step();
  REQUIRE(r.submit(Rig::force(1.0, 0.05)));
  int settled_cycles = 0;
  double worst = 0;
  for (int i = 0; i < 3000; ++i) {
    r.hand.pressure_valid = i % 3 == 2 ? 0x00 : 0x1F;
    r.step();
    if (i > 1000) {
      settled_cycles += r.st.settled;
      worst = std::max(worst, std::fabs(r.plant_force() - 1.0));
      CHECK(r.st.force_n[0] > 0.9f);  // never read as 0 N
    }
  }
  MESSAGE("every third sample missing: true force within " << worst << " N of 1 N, settled in " << settled_cycles
                                                             << " of the last 1999 cycles");
  CHECK(worst < 0.05);
  CHECK(settled_cycles > 1900);
}

TEST_CASE("parameters: bad ones are refused with file, line and key") {
  auto error_of = [](const std::string& extra, const std::string& side = "left") {
    try {
      (void)config(extra, side);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error_of("alpha: {FFJ3: 1, FFJ7: 0.2}").find("force.params.alpha.FFJ7: unknown joint 'FFJ7' (did you mean") !=
        std::string::npos);
  CHECK(error_of("alpha: {THJ2: 1}").find("force.params.alpha.THJ2: not a finger's flexion joint") != std::string::npos);
  CHECK(error_of("alpha: {FFJ3: 0.2, FFJ2: 0.5}").find("force.params.alpha.FFJ2: alpha of FFJ2 must not exceed") !=
        std::string::npos);
  CHECK(error_of("alpha: {FFJ3: -1}").find("force.params.alpha.FFJ3: must be in [0, 10]") != std::string::npos);
  CHECK(error_of("joint_stiffness: {WRJ3: 20}").find("force.params.joint_stiffness.WRJ3: unknown joint 'WRJ3' (did you mean") !=
        std::string::npos);
  CHECK(error_of("joint_stiffness: {WRJ1: 700}").find("force.params.joint_stiffness.WRJ1: must be in [0, 655.35]") !=
        std::string::npos);
  CHECK(error_of("k_p: -2").find("f.yaml:1:") == 0);
  CHECK(error_of("k_p: -2").find("force.params.k_p: must be in [0, 100], got -2") != std::string::npos);
  CHECK(error_of("on_bad_input: panic").find("force.params.on_bad_input: expected hold or retreat") != std::string::npos);
  CHECK(error_of("force_limit_n: 2, max_goal_force_n: 3").find("max_goal_force_n: must be below force_limit_n") !=
        std::string::npos);
  CHECK(error_of("force_limit_samples: 0")
            .find("force.params.force_limit_samples: must be in [1, 1000]") != std::string::npos);
  CHECK(error_of("start: stiff").find("force.params.start: expected limp or hold, got 'stiff'") != std::string::npos);
  CHECK(error_of("", "middle").find("force.params.side: expected right or left") != std::string::npos);
  CHECK(error_of("") == "no error");
}

TEST_CASE("a cycle allocates nothing") {
  Rig r(config());
  r.step();
  REQUIRE(r.submit(Rig::force(1.0, 0.05)));
  const auto before = rt::rt_allocation_count();
  {
    rt::ScopedRtMark rt;
    r.steps(1000);
    (void)r.submit(Rig::hold());
    r.steps(10);
  }
  CHECK(rt::rt_allocation_count() == before);
}
