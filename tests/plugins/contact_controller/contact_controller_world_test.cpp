// C_contact against the simulated world (tests/support/hand_world.h): an index fingertip moved
// down onto the sheet at 20 mm/s by the arm is stopped on the contact the controller reports,
// scored from the world's truth: how many cycles after the world's first contact it was
// detected, how deep the fingertip went into the sheet, the contact force at the stop. The
// debounce shown to matter (off, the sensors' noise alone makes contacts), and 60 s of free
// motion without a false contact. The hands' joints at 6 N m/rad during the approach (seed
// 000: "the controllable joint stiffness and the employed threshold ... select an appropriate
// contact force"); the controllers' defaults otherwise.
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

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

namespace {

// The arm moves the hand to and fro 60 mm sideways at 20 mm/s, 10 mm over the sheet, for
// SECONDS; returns the contact onsets the controller reported.
std::uint64_t free_motion(robot::Side side, const std::string& contact_params, double seconds, double joint_noise_rad = 0) {
  Options o = approach_options(side, contact_params);
  o.start = {side == robot::Side::left ? -20.0 : 20.0, 40, 16};
  o.joint_noise_rad = joint_noise_rad;
  HandWorld w(o);
  REQUIRE(w.run_until([&] { return w.contact().armed != 0; }, 1.0));
  const double dx = side == robot::Side::left ? -60.0 : 60.0;
  const ArmPath out = w.line(o.start, {o.start.x + dx, o.start.y, o.start.z}, 0.5);
  const ArmPath back = w.line({o.start.x + dx, o.start.y, o.start.z}, o.start, 0.5);
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

namespace {

// The parameters config/sim.yaml gives the contact controller NAME, as the harness's "k: v, ..."
// entries (the right hand's: Eq. 5's threshold at the wire's resolution, the taxels OR'ed).
std::string shipped_params(const std::string& name) {
  const YAML::Node root = YAML::LoadFile(std::string(CREASE_SOURCE_DIR) + "/config/sim.yaml");
  std::string out;
  for (const auto& pl : root["plugins"]) {
    if (pl["name"].as<std::string>() != name) continue;
    for (auto it = pl["params"].begin(); it != pl["params"].end(); ++it)
      out += (out.empty() ? "" : ", ") + it->first.as<std::string>() + ": " + it->second.as<std::string>();
  }
  REQUIRE_MESSAGE(!out.empty(), name);
  return out;
}

struct Trials {
  std::vector<long> latency;  // cycles, per trial
  double max_penetration_mm = 0, min_force_at_stop_n = 1e9, max_force_at_stop_n = 0, max_force_after_n = 0;
  int missed = 0;
  int not_index = 0;  // onsets whose fingers did not include the index (the one touching)
  [[nodiscard]] long worst() const { return latency.empty() ? -1 : *std::max_element(latency.begin(), latency.end()); }
  [[nodiscard]] long best() const { return latency.empty() ? -1 : *std::min_element(latency.begin(), latency.end()); }
  [[nodiscard]] std::string histogram() const {
    std::map<long, int> h;
    for (long l : latency) ++h[l];
    std::string s;
    for (const auto& [l, n] : h) s += std::to_string(n) + " x " + std::to_string(l) + "  ";
    return s;
  }
};

// N approaches of the right index onto the sheet at 20 mm/s from heights stepped by 3.7 um
// (over 0.09 mm: every phase of the world's 20 um steps, the wire's 1e-4 rad quanta and the
// taxels' 4 ms sampling), each with its own noise seed; with CONTACT_PARAMS, and joint noise
// JOINT_NOISE_RAD (the simulated joints read exactly).
Trials right_trials(int n, const std::string& contact_params, double joint_noise_rad = 0, int after_cycles = 300) {
  Trials t;
  for (int i = 0; i < n; ++i) {
    Options o = approach_options(robot::Side::right, contact_params);
    o.start = {20, 40, 6.0 + 0.0037 * i};  // the pad touches the sheet about 0.85 mm lower
    o.sensor_seed = 101 + static_cast<std::uint64_t>(i);
    o.joint_noise_rad = joint_noise_rad;
    HandWorld w(o);
    if (!w.approach(20.0, 4.0)) {
      ++t.missed;
      continue;
    }
    t.latency.push_back(w.first_contact_cycle() - w.first_world_contact_step());
    if ((w.contact().fingers & 0x01) == 0) ++t.not_index;
    t.min_force_at_stop_n = std::min(t.min_force_at_stop_n, w.force_n());
    t.max_force_at_stop_n = std::max(t.max_force_at_stop_n, w.force_n());
    for (int k = 0; k < after_cycles; ++k) {
      w.cycle();
      t.max_penetration_mm = std::max(t.max_penetration_mm, w.world().max_penetration_mm());
    }
    t.max_force_after_n = std::max(t.max_force_after_n, w.force_n());
  }
  return t;
}

}  // namespace

TEST_CASE("C_contact, right hand (config/sim.yaml's contact_r): detected within 3 cycles of the world's first contact over "
          "24 trials (failing variant: Delta theta_max at the former 2 mrad)") {
  const std::string shipped = shipped_params("contact_r");
  const Trials t = right_trials(24, shipped);
  MESSAGE("right hand, " << shipped << ": latency over " << t.latency.size() << " trials: " << t.histogram()
                         << "(cycles); force at the stop " << t.min_force_at_stop_n << " .. " << t.max_force_at_stop_n
                         << " N, at most " << t.max_force_after_n << " N 0.3 s later; worst depth " << t.max_penetration_mm
                         << " mm");
  CHECK(t.not_index == 0);  // the onset names the finger touching (arm_motion's stop condition is by finger)
  CHECK(t.missed == 0);
  CHECK(t.latency.size() == 24);
  CHECK(t.best() >= 1);   // the world's state reaches the controller one cycle later
  CHECK(t.worst() <= 3);  // the target
  CHECK(t.max_penetration_mm <= 1.0);
  // The stated band: a few mN when detected (the deviation grows 0.11 mrad a cycle at 20 mm/s,
  // whatever the stiffness: the finger is the compliant part), under 0.1 N once the arm has
  // stopped (1 m/s^2 from 20 mm/s: 0.2 mm further).
  CHECK(t.min_force_at_stop_n > 0.001);
  CHECK(t.max_force_at_stop_n < 0.03);
  CHECK(t.max_force_after_n < 0.1);

  SUBCASE("failing variant: Eq. 5 at 2 mrad (the controller's default), the taxels OR'ed: 19 cycles") {
    const Trials f = right_trials(24, "tactile: taxels, tactile_enter_kpa: 8, tactile_exit_kpa: 4", 0.0, 0);
    MESSAGE("right hand, 2 mrad: latency over " << f.latency.size() << " trials: " << f.histogram() << "(cycles)");
    CHECK(f.best() > 3);
    CHECK(f.worst() <= 25);
  }
  SUBCASE("the taxels alone (the joints' test out of reach): they need 0.35 N, 90 cycles and more") {
    const Trials f = right_trials(8, "tactile: taxels, tactile_enter_kpa: 8, tactile_exit_kpa: 4, enter_rad: 1.0, exit_rad: 0.5",
                                  0.0, 0);
    MESSAGE("right hand, taxels alone: latency " << f.histogram() << "(cycles); force at the stop " << f.min_force_at_stop_n
                                                 << " .. " << f.max_force_at_stop_n << " N");
    CHECK(f.best() > 50);
    CHECK(f.min_force_at_stop_n > 0.2);
  }
}

TEST_CASE("C_contact, right hand with noisy joints: the measured noise raises Delta theta_max, no false contact in free motion "
          "(failing variant: noise_factor and spike_margin 0, the threshold at the wire's resolution fires on the noise)") {
  const std::string shipped = shipped_params("contact_r");
  for (const double sigma : {2e-5, 5e-5}) {
    CAPTURE(sigma);
    const double seconds = sigma < 3e-5 ? 60.0 : 21.0;  // the finer noise flickers rarely: the longer run
    const std::uint64_t guarded = free_motion(robot::Side::right, shipped, seconds, sigma);
    const std::uint64_t bare = free_motion(robot::Side::right, shipped + ", noise_factor: 0, spike_margin: 0", 6.0, sigma);
    const Trials t = right_trials(8, shipped, sigma, 0);
    MESSAGE("joint noise " << sigma * 1e3 << " mrad: false contacts: " << guarded << " in " << seconds << " s guarded, " << bare
                           << " in 6 s"
                           << " unguarded; latency guarded " << t.histogram() << "(cycles)");
    CHECK(guarded == 0);
    CHECK(bare > 0);
    CHECK(t.missed == 0);
  }
}


TEST_CASE("free motion: no false contact in 60 s; with the debounce off, sensor noise alone makes contacts") {
  const std::uint64_t debounced = free_motion(robot::Side::left, "", 60.0);
  const std::uint64_t raw = free_motion(robot::Side::left, "debounce_cycles: 1", 60.0);
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
