// C_contact (seed 000 Eq. 5) on synthetic hand states: it arms once the hand has settled,
// fires when the P-weighted deviation passes Delta theta_max for the debounce's cycles, or a
// fingertip's pressure passes its tared baseline, releases below the lower exit threshold,
// freezes on stale or faulty input, and its parameters are checked with file, line and key.
// Each behaviour beside the variant with the feature off.
#include "plugins/contact_controller/contact_detector.h"

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "plugins/contact_controller/contact_params.h"
#include "rt/alloc_guard.h"

using namespace crease;
using namespace crease::contact;

namespace {

constexpr int FFJ3 = 3, FFJ2 = 4, MFJ3 = 6, THJ4 = 16, WRJ1 = 1;

ContactConfig config(const std::string& yaml = "{}") {
  return read_contact_config(Params(YAML::Load(yaml), "c.yaml", "contact.params"));
}

// Feeds the detector one synthetic cycle at a time.
struct Rig {
  explicit Rig(const ContactConfig& c) : d(c) {
    hand.health = DeviceHealth::ok;
    hand.fresh = 1;
    hand.pressure_valid = 0x1F;
    for (int f = 0; f < 5; ++f) hand.pressure_kpa[f] = 0.2f;  // an offset the tare takes out
  }
  bool step(bool fresh = true) {
    ContactInputs in;
    in.time_ns = t;
    in.hand = &hand;
    in.hand_new = fresh;
    in.command = with_command ? &command : nullptr;
    in.tactile = with_tactile ? &tactile : nullptr;
    if (tactile_streaming) tactile.timestamp_ns = t;
    t += 1'000'000;
    const bool e = d.step_rt(in, out, event);
    if (e) events.push_back(event);
    return e;
  }
  void steps(int n) {
    for (int i = 0; i < n; ++i) step();
  }
  void arm() {
    steps(d.config().settle_cycles + 1);
    REQUIRE(out.armed == 1);
  }
  int onsets() const {
    int n = 0;
    for (const auto& e : events) n += e.onset;
    return n;
  }
  ContactDetector d;
  HandState hand;
  HandCommand command;
  Tactile tactile;
  bool with_command = false, with_tactile = false, tactile_streaming = true;
  ContactState out;
  ContactEvent event;
  std::vector<ContactEvent> events;
  std::int64_t t = 1'000'000'000;
};

}  // namespace

TEST_CASE("the thresholds in use rise with the joints' noise measured at arming, and with each spike the debounce "
          "rejected (failing variant: noise_factor and spike_margin 0)") {
  for (const bool guarded : {true, false}) {
    CAPTURE(guarded);
    Rig r(config(guarded ? "{enter_rad: 0.00005, exit_rad: 0.00003}"
                         : "{enter_rad: 0.00005, exit_rad: 0.00003, noise_factor: 0, spike_margin: 0}"));
    // Settling: FFJ3 alternates by 0.2 mrad (a noise of 0.1 mrad about its mean of 0.1 mrad).
    for (int i = 0; i < 51; ++i) {
      r.hand.position_rad[FFJ3] = (i % 2 == 0) ? 0.0f : 0.0002f;
      r.step();
    }
    REQUIRE(r.out.armed == 1);
    if (guarded) CHECK(r.out.threshold_rad == doctest::Approx(3 * 1e-4).epsilon(1e-3));  // noise_factor 3 x 0.1 mrad
    else CHECK(r.out.threshold_rad == doctest::Approx(5e-5));
    // The same noise goes on: never a contact when guarded; every other cycle over 50 urad bare.
    for (int i = 0; i < 200; ++i) {
      r.hand.position_rad[FFJ3] = (i % 2 == 0) ? 0.0f : 0.0002f;
      r.step();
    }
    CHECK(r.onsets() == (guarded ? 0 : 1));
  }
  SUBCASE("a rare spike, unseen while settling, raises the threshold to spike_margin x its peak") {
    Rig r(config("{enter_rad: 0.00005, exit_rad: 0.00003}"));
    r.arm();
    CHECK(r.out.threshold_rad == doctest::Approx(5e-5));
    r.hand.position_rad[WRJ1] = 0.0001f;  // one cycle one wire unit off, then back
    r.step();
    r.hand.position_rad[WRJ1] = 0.0f;
    r.step();
    CHECK(r.out.in_contact == 0);
    CHECK(r.d.state().spikes == 1);
    CHECK(r.out.threshold_rad == doctest::Approx(1.5e-4).epsilon(1e-3));
    // Now two cycles in a row of the same spike do not make a contact; 0.2 mrad does.
    for (int i = 0; i < 2; ++i) {
      r.hand.position_rad[WRJ1] = 0.0001f;
      r.step();
    }
    CHECK(r.out.in_contact == 0);
    r.hand.position_rad[WRJ1] = 0.0002f;
    r.steps(2);
    CHECK(r.out.in_contact == 1);
  }
}

TEST_CASE("C_contact arms once the hand has settled, not while it moves") {
  Rig r(config("{settle_cycles: 50}"));
  for (int i = 0; i < 200; ++i) {  // moving 2 mrad a cycle: never settled
    r.hand.position_rad[FFJ3] = 0.002f * static_cast<float>(i);
    r.step();
    CHECK(r.out.armed == 0);
  }
  r.steps(48);  // the last moving cycle starts the window: 49 of 50
  CHECK(r.out.armed == 0);
  r.step();
  CHECK(r.out.armed == 1);
  CHECK(r.out.in_contact == 0);
  CHECK(r.out.deviation_rad == 0.0f);
}

TEST_CASE("Eq. 5: contact once the P-weighted deviation exceeds Delta theta_max for the debounce's cycles") {
  Rig r(config("{enter_rad: 0.002, exit_rad: 0.001, debounce_cycles: 3}"));
  r.arm();
  const float ref = r.hand.position_rad[FFJ3];
  // Deviate FFJ3 by 0.1 mrad a cycle: over 2 mrad from the 21st cycle, then 3 cycles in a row.
  int onset_at = -1;
  for (int i = 1; i <= 40 && onset_at < 0; ++i) {
    r.hand.position_rad[FFJ3] = ref + 0.0001f * static_cast<float>(i);
    if (r.step()) onset_at = i;
  }
  CHECK(onset_at == 23);
  CHECK(r.out.in_contact == 1);
  CHECK(r.out.fingers == 0b00001);  // the first finger
  CHECK(r.out.source == contact_joints);
  CHECK(r.out.since_ns == r.event.timestamp_ns);
  CHECK(r.out.onsets == 1);
  CHECK(r.event.onset == 1);
  CHECK(r.out.deviation_rad == doctest::Approx(0.0023).epsilon(0.01));
  CHECK(r.out.finger_deviation_rad[0] == doctest::Approx(r.out.deviation_rad));

  SUBCASE("the norm is P's: two selected joints add in quadrature with their weights") {
    Rig w(config("{weights: {FFJ3: 1, MFJ3: 4}, enter_rad: 0.002, exit_rad: 0.001}"));
    w.arm();
    w.hand.position_rad[FFJ3] += 0.001f;
    w.hand.position_rad[MFJ3] += 0.001f;  // sqrt(1 x 1e-6 + 4 x 1e-6) = 2.24 mrad
    w.step();
    CHECK(w.out.deviation_rad == doctest::Approx(std::sqrt(5.0) * 1e-3).epsilon(1e-3));
    CHECK(w.out.finger_deviation_rad[1] == doctest::Approx(2e-3).epsilon(1e-3));
  }
}

TEST_CASE("P selects: a joint of weight 0 deviating is no contact (failing variant: weighted, it is)") {
  for (const bool selected : {false, true}) {
    CAPTURE(selected);
    Rig r(config(selected ? "{weights: {FFJ3: 1, THJ4: 1}}" : "{weights: {FFJ3: 1}}"));
    r.arm();
    r.hand.position_rad[THJ4] += 0.05f;
    r.steps(5);
    CHECK(r.out.in_contact == (selected ? 1 : 0));
    if (selected) CHECK(r.out.fingers == 0b10000);  // the thumb
  }
}

TEST_CASE("the debounce: a one-cycle spike is no contact (failing variant: debounce_cycles 1)") {
  for (const int n : {2, 1}) {
    CAPTURE(n);
    Rig r(config("{debounce_cycles: " + std::to_string(n) + "}"));
    r.arm();
    const float ref = r.hand.position_rad[WRJ1];
    r.hand.position_rad[WRJ1] = ref + 0.01f;
    r.step();
    r.hand.position_rad[WRJ1] = ref;
    r.steps(10);
    CHECK(r.onsets() == (n == 1 ? 1 : 0));
  }
}

TEST_CASE("hysteresis: between the exit and enter thresholds a contact stays (failing variant: exit just below enter)") {
  for (const double exit : {0.001, 0.00199}) {
    CAPTURE(exit);
    Rig r(config("{enter_rad: 0.002, exit_rad: " + std::to_string(exit) + ", debounce_cycles: 2}"));
    r.arm();
    const float ref = r.hand.position_rad[FFJ3];
    r.hand.position_rad[FFJ3] = ref + 0.003f;
    r.steps(3);
    REQUIRE(r.out.in_contact == 1);
    // A deviation wavering about 2 mrad, +-0.5 mrad, slowly: a contact that persists.
    for (int i = 0; i < 400; ++i) {
      r.hand.position_rad[FFJ3] = ref + 0.002f + 0.0005f * static_cast<float>(std::sin(i * 0.05));
      r.step();
    }
    if (exit < 0.0015) CHECK(r.onsets() == 1);
    else CHECK(r.onsets() > 2);  // it chatters
    // Released below the exit threshold, after the debounce.
    r.hand.position_rad[FFJ3] = ref;
    r.steps(1);
    CHECK(r.out.in_contact == 1);
    r.steps(1);
    CHECK(r.out.in_contact == 0);
    CHECK(r.events.back().onset == 0);
    CHECK(r.events.back().fingers == 0);
  }
}

TEST_CASE("tactile contact OR'ed with the joints: a PST pressure above its tared baseline (failing variant: tactile none)") {
  for (const bool tactile : {true, false}) {
    CAPTURE(tactile);
    Rig r(config(tactile ? "{tactile: pst, tactile_enter_kpa: 0.03, tactile_exit_kpa: 0.015}" : "{tactile: none}"));
    r.arm();  // tares the 0.2 kPa offset
    CHECK(r.out.in_contact == 0);
    r.hand.pressure_kpa[2] = 0.25f;  // ring finger: 0.05 kPa over its baseline, no joint moves
    r.steps(2);
    CHECK(r.out.in_contact == (tactile ? 1 : 0));
    if (tactile) {
      CHECK(r.out.fingers == 0b00100);
      CHECK(r.out.source == contact_tactile);
    }
  }
}

// hand_state's pressure_valid is per cycle: a cycle whose pressure frame did not come in has
// none. The sensor then reads as its last sample, so a press whose frames come every other
// cycle still debounces into a contact (failing variant, a missing sample read as no
// pressure: the tactile test's run restarts every other cycle and never reaches the debounce).
TEST_CASE("a cycle without a PST sample reads as the last one: a press with every other sample missing is a contact") {
  Rig r(config("{tactile: pst, tactile_enter_kpa: 0.03, tactile_exit_kpa: 0.015}"));
  r.arm();
  r.hand.pressure_kpa[2] = 0.25f;
  for (int i = 0; i < 20; ++i) {
    r.hand.pressure_valid = i % 2 == 0 ? 0x1F : 0x00;
    r.step();
  }
  CHECK(r.out.in_contact == 1);
  CHECK(r.out.fingers == 0b00100);
  CHECK(r.onsets() == 1);
  // Released: the samples that come read the baseline again, and the contact ends.
  r.hand.pressure_kpa[2] = 0.2f;
  for (int i = 0; i < 20; ++i) {
    r.hand.pressure_valid = i % 2 == 0 ? 0x1F : 0x00;
    r.step();
  }
  CHECK(r.out.in_contact == 0);
}

TEST_CASE("the baseline follows a slow drift of untouched sensors (failing variant: a baseline that does not follow)") {
  for (const double tau : {1.0, 1e4}) {
    CAPTURE(tau);
    Rig r(config("{tactile: pst, baseline_time_constant_s: " + std::to_string(tau) + "}"));
    r.arm();
    for (int i = 0; i < 60'000; ++i) {  // 60 s drifting 0.002 kPa/s, as the PST's figure
      for (int f = 0; f < 5; ++f) r.hand.pressure_kpa[f] = 0.2f + 0.002f * static_cast<float>(i) * 1e-3f;
      r.step();
    }
    CHECK(r.onsets() == (tau < 10 ? 0 : 1));
  }
}

TEST_CASE("taxels: a fingertip's taxel sum above its baseline; samples older than the bound are stale") {
  Rig r(config("{tactile: taxels, tactile_enter_kpa: 8, tactile_exit_kpa: 4, max_tactile_age_ms: 20}"));
  r.with_tactile = true;
  r.tactile.health = DeviceHealth::ok;
  r.tactile.valid = 0x1F;
  r.arm();
  r.tactile.pressure_kpa[1][10] = 12.0f;  // one taxel of the middle finger
  r.steps(2);
  CHECK(r.out.in_contact == 1);
  CHECK(r.out.fingers == 0b00010);
  r.tactile_streaming = false;  // the sensor falls silent
  r.steps(20);
  CHECK(r.out.healthy == 1);  // 20 ms: within the bound
  r.steps(1);
  CHECK(r.out.healthy == 0);
}

TEST_CASE("the commanded targets: flexing in contact is not more contact; a new posture out of contact re-arms") {
  Rig r(config("{enter_rad: 0.002, exit_rad: 0.001, rearm_rad: 0.01, settle_cycles: 20}"));
  r.with_command = true;
  r.arm();
  // Out of contact, the command moves FFJ3 by 0.05 rad and the hand follows: no contact, but
  // the controller disarms and takes the new pose once settled.
  for (int i = 1; i <= 50; ++i) {
    r.command.target_rad[FFJ3] = 0.001f * static_cast<float>(i);
    r.hand.position_rad[FFJ3] = r.command.target_rad[FFJ3];
    r.step();
  }
  CHECK(r.out.armed == 0);
  CHECK(r.onsets() == 0);
  r.steps(21);
  CHECK(r.out.armed == 1);
  // In contact (the finger held 3 mrad short of its target), the force controller flexes the
  // target on by 0.05 rad: the deviation from the relaxed pose under that command stays 3 mrad.
  r.command.target_rad[FFJ3] += 0.003f;
  r.steps(3);
  REQUIRE(r.out.in_contact == 1);
  for (int i = 0; i < 50; ++i) {
    r.command.target_rad[FFJ3] += 0.001f;
    r.step();
  }
  CHECK(r.out.in_contact == 1);
  CHECK(r.out.deviation_rad == doctest::Approx(0.003).epsilon(0.05));
  CHECK(r.out.armed == 1);

  SUBCASE("failing variant: without the commanded targets, the flexing reads as a deviation over ten times larger") {
    Rig b(config("{enter_rad: 0.002, exit_rad: 0.001}"));
    b.arm();
    b.command.target_rad[FFJ3] = 0.003f;
    for (int i = 0; i < 50; ++i) {
      b.hand.position_rad[FFJ3] += 0.001f;  // the finger flexes on with its target, 3 mrad short
      b.step();
    }
    CHECK(b.out.deviation_rad > 0.04f);
  }
}

TEST_CASE("stale or faulty hand_state: healthy 0, no onset, no release on stale data") {
  Rig r(config("{stale_cycles: 3}"));
  r.arm();
  SUBCASE("no fresh status: tolerated for stale_cycles, then frozen and disarmed") {
    for (int i = 0; i < 3; ++i) r.step(false);
    CHECK(r.out.healthy == 1);
    r.step(false);
    CHECK(r.out.healthy == 0);
    r.hand.position_rad[FFJ3] += 0.01f;  // what a stale status would show: never acted on
    for (int i = 0; i < 10; ++i) r.step(false);
    CHECK(r.out.healthy == 0);
    CHECK(r.out.armed == 0);
    CHECK(r.onsets() == 0);
  }
  SUBCASE("health fault: at once; a contact in progress is kept, not released") {
    r.hand.position_rad[FFJ3] += 0.01f;
    r.steps(3);
    REQUIRE(r.out.in_contact == 1);
    r.hand.health = DeviceHealth::fault;
    r.hand.position_rad[FFJ3] -= 0.01f;
    r.steps(10);
    CHECK(r.out.healthy == 0);
    CHECK(r.out.in_contact == 1);
    CHECK(r.events.size() == 1);
  }
  SUBCASE("degraded counts as not fresh") {
    r.hand.health = DeviceHealth::degraded;
    r.steps(4);
    CHECK(r.out.healthy == 0);
  }
}

TEST_CASE("state carried across a hot-swap: a restored detector goes on where the old one was") {
  Rig a(config());
  a.arm();
  a.hand.position_rad[FFJ3] += 0.003f;
  a.steps(3);
  REQUIRE(a.out.in_contact == 1);
  Rig b(config());
  b.hand = a.hand;
  b.t = a.t;
  b.d.restore(a.d.state());
  a.step();
  b.step();
  CHECK(b.out.in_contact == 1);
  CHECK(b.out.armed == 1);
  CHECK(b.out.since_ns == a.out.since_ns);
  CHECK(b.out.deviation_rad == a.out.deviation_rad);
  CHECK(b.events.empty());  // no second onset
  Rig fresh(config());      // without the state: not even armed
  fresh.hand = a.hand;
  fresh.step();
  CHECK(fresh.out.armed == 0);
}

TEST_CASE("parameters: bad ones are refused with file, line and key") {
  auto error_of = [](const std::string& yaml) {
    try {
      (void)config(yaml);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error_of("{weights: {FFJ3: 1,\n  FFJ9: 1}}").find("c.yaml:2:9: contact.params.weights.FFJ9: unknown joint 'FFJ9' (did you mean") == 0);
  CHECK(error_of("{weights: {FFJ3: -1}}").find("contact.params.weights.FFJ3: must be in [0, 100], got -1") != std::string::npos);
  CHECK(error_of("{weights: {FFJ3: 0}}").find("contact.params.weights: selects no joint") != std::string::npos);
  CHECK(error_of("{enter_rad: 0.002, exit_rad: 0.003}").find("contact.params.exit_rad: must be below enter_rad") != std::string::npos);
  CHECK(error_of("{enter_rad: -1}").find("contact.params.enter_rad: must be in") != std::string::npos);
  CHECK(error_of("{debounce_cycles: 0}").find("contact.params.debounce_cycles: must be in [1, 1000]") != std::string::npos);
  CHECK(error_of("{tactile: piezo}").find("contact.params.tactile: expected none, pst") != std::string::npos);
  CHECK(error_of("{tactile_enter_kpa: 0.01, tactile_exit_kpa: 0.02}").find("tactile_exit_kpa: must be below") != std::string::npos);
  CHECK(error_of("{}") == "no error");
}

TEST_CASE("a cycle allocates nothing") {
  Rig r(config("{tactile: pst}"));
  r.arm();
  r.events.reserve(1000);
  const auto before = rt::rt_allocation_count();
  {
    rt::ScopedRtMark rt;
    for (int i = 0; i < 1000; ++i) {
      r.hand.position_rad[FFJ2] = 0.004f * static_cast<float>(i % 2);
      r.step();
    }
  }
  CHECK(rt::rt_allocation_count() == before);
}
