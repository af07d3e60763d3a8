// The arm motion controller driving the simulated world's arm (World::command_arm_rt from its
// command, one world step per control cycle): a motion brings the world's fingertip pad to its
// target within 0.05 mm and 0.1 mrad, scored from world.state(); a descent onto the sheet
// stopped by a contact onset (taken from the world's own contact flag, standing in for the
// contact controller) decelerates within the stop limit, measured from the world's applied
// arm angles; and the chain: contact_r's detector (config/sim.yaml's parameters) on the world's
// hand angles stopping the descent.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include <yaml-cpp/yaml.h>

#include <string>

#include "motion_rig.h"
#include "plugins/contact_controller/contact_detector.h"
#include "plugins/contact_controller/contact_params.h"
#include "plugins/sim_world/sim_world.h"

using namespace rig;
using crease::world::World;
using crease::world::WorldParams;

namespace {

// The left arm parked with its palm 150 mm above the table on its side (arm_motion's left rest posture).
Joints left_park() { return {0.535, -0.993, 0.426, 1.890, -0.819, 1.124, -2.230}; }

struct WorldRig {
  WorldRig() {
    WorldParams p;
    p.randomise = false;
    p.initial_arm_rad[0] = start_posture();
    p.initial_arm_rad[1] = left_park();
    world = std::make_unique<World>(model(), p);
    stiffness.fill(p.initial_stiffness_nm_per_rad);
    motion = std::make_unique<ArmMotion>(model(), Side::right, params());
    contact.armed = 1;
    contact.healthy = 1;
  }

  // One control cycle: the arm's state from the world, the controller, the command to the
  // world, one world step.
  void cycle(const ArmGoal* goal = nullptr) {
    now += kPeriod;
    ArmState arm;
    arm.timestamp_ns = now;
    arm.valid = 0x7f;
    arm.fresh = 1;
    arm.drive_state = 4;
    arm.health = DeviceHealth::ok;
    const auto& q = world->arm_angles(Side::right);
    for (int j = 0; j < robot::kArmJoints; ++j) arm.position_rad[j] = static_cast<float>(q[j]);
    HandState hand;
    hand.timestamp_ns = now;
    hand.health = DeviceHealth::ok;
    const auto& h = world->hand_angles(Side::right);
    for (int j = 0; j < robot::kHandJoints; ++j) hand.position_rad[j] = static_cast<float>(h[j]);
    contact.timestamp_ns = now;
    CycleInputs in;
    in.now_ns = now;
    in.arm = &arm;
    in.hand = &hand;
    in.contact = &contact;
    if (goal != nullptr) motion->on_goal(*goal, in, nullptr);
    if (motion->step(in)) {
      Joints cmd{};
      for (int j = 0; j < robot::kArmJoints; ++j) cmd[j] = motion->command().position_rad[j];
      world->command_arm_rt(Side::right, cmd);
    }
    world->command_arm_rt(Side::left, left_park());
    world->command_hand_rt(Side::right, hand_target, stiffness);
    world->command_hand_rt(Side::left, hand_target, stiffness);
    world->step_rt();
  }
  [[nodiscard]] bool active() const {
    const auto s = motion->status().state;
    return s == ArmMotionStatus::checking || s == ArmMotionStatus::running || s == ArmMotionStatus::stopping;
  }
  // The world's index fingertip pad (its truth, mm and rotation).
  [[nodiscard]] KDL::Frame pad() const {
    const WorldFingertip& t = world->state().hand[0].tip[0];
    const float* r = t.rotation;
    return KDL::Frame(KDL::Rotation(r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8]),
                      KDL::Vector(t.position_mm[0], t.position_mm[1], t.position_mm[2]) / 1000.0);
  }
  // The pad from the world's applied arm angles (double: for accelerations), the hand at its
  // commanded posture (the arm's motion, without the fingers' deflection on contact).
  [[nodiscard]] KDL::Vector pad_applied() const {
    Joints q{};
    const auto& a = world->arm_angles(Side::right);
    for (int j = 0; j < robot::kArmJoints; ++j) q[j] = a[j];
    Hand hq{};
    for (int j = 0; j < robot::kHandJoints; ++j) hq[j] = hand_target[j];
    KDL::Frame f;
    REQUIRE(model().tool_pose_m(Side::right, ToolFrame::ff_pad, q, hq, f));
    return f.p;
  }

  std::unique_ptr<World> world;
  std::unique_ptr<ArmMotion> motion;
  World::HandJoints hand_target{}, stiffness{};
  ContactState contact;
  std::int64_t now = 1'000'000'000;
};

}  // namespace

TEST_CASE("a motion brings the world's fingertip pad to its target within 0.05 mm and 0.1 mrad") {
  WorldRig w;
  for (int i = 0; i < 5; ++i) w.cycle();
  const KDL::Frame start = w.pad();
  const KDL::Frame target(KDL::Rotation::RotZ(0.2) * KDL::Rotation::RotY(-0.1) * start.M,
                          start.p + KDL::Vector(0.05, 0.04, -0.08));
  const ArmGoal g = goal_to(ToolFrame::ff_pad, target, 21, 120, 1200);
  w.cycle(&g);
  int n = 0;
  while (w.active() && n++ < 10000) w.cycle();
  REQUIRE(w.motion->status().state == ArmMotionStatus::reached);
  for (int i = 0; i < 20; ++i) w.cycle();  // held
  const KDL::Frame end = w.pad();
  const double err_mm = mm(end.p - target.p), err_mrad = 1e3 * rot_angle(end.M, target.M);
  std::printf("world pad: %.2g mm, %.2g mrad from the target after %d cycles\n", err_mm, err_mrad, n);
  CHECK(err_mm < 0.05);
  CHECK(err_mrad < 0.1);
  CHECK(w.world->state().rate_limited == 0);  // the world never had to slow the arm down
  CHECK(w.world->state().clamped_targets == 0);
}

TEST_CASE("a descent onto the sheet stopped on the contact onset decelerates within the stop limit") {
  WorldRig w;
  for (int i = 0; i < 5; ++i) w.cycle();
  // The fingers tilted 40 deg down (the shoulders are 983 mm above the table: a flat hand
  // would need the arm stretched), the pad 10 mm above the sheet (at most 0.5 mm thick).
  const KDL::Frame start(KDL::Rotation::RotX(-0.7) * w.pad().M, w.pad().p);
  ArmGoal above = goal_to(ToolFrame::ff_pad, KDL::Frame(start.M, KDL::Vector(start.p.x(), start.p.y(), 0.012)), 22,
                          80, 800);
  above.angular_speed_rad_s = 0.4f;
  w.cycle(&above);
  while (w.active()) w.cycle();
  CAPTURE(static_cast<int>(w.motion->status().reason));
  REQUIRE(w.motion->status().state == ArmMotionStatus::reached);
  // Then on down at 20 mm/s to 5 mm below the table, stopping on a contact onset.
  ArmGoal down = goal_to(ToolFrame::ff_pad, KDL::Frame(start.M, KDL::Vector(start.p.x(), start.p.y(), -0.005)), 23, 20,
                         200);
  down.stop_on = ArmGoal::contact_onset;
  down.stop_accel_mm_s2 = 2000;
  w.cycle(&down);
  std::vector<KDL::Vector> p;
  int onset_cycle = -1;
  for (int i = 0; i < 5000 && w.active(); ++i) {
    bool touching = false;
    for (const auto& t : w.world->state().hand[0].tip) touching = touching || t.contact != 0;
    if (touching && w.contact.in_contact == 0) {  // the world's first contact: an onset
      w.contact.in_contact = 1;
      w.contact.fingers = 0x1f;
      ++w.contact.onsets;
      onset_cycle = static_cast<int>(p.size());
    }
    w.cycle();
    p.push_back(w.pad_applied());
  }
  REQUIRE(onset_cycle >= 2);
  CHECK(w.motion->status().state == ArmMotionStatus::stopped_on_contact);
  const auto speed = [&](std::size_t i) { return 1e6 * norm((p[i] - p[i - 1])); };  // mm/s
  double max_decel = 0;
  for (std::size_t i = static_cast<std::size_t>(onset_cycle) + 1; i < p.size(); ++i) {
    max_decel = std::max(max_decel, 1e3 * std::abs(speed(i) - speed(i - 1)));
  }
  const double v_onset = speed(static_cast<std::size_t>(onset_cycle) - 1);
  const double travel_mm = 1e3 * norm((p.back() - p[static_cast<std::size_t>(onset_cycle) - 1]));
  std::printf("stop on contact: %zu cycles, %.1f mm/s at the onset, decelerated at up to %.0f mm/s^2, %.3f mm further, "
              "penetration %.3f mm\n",
              p.size() - static_cast<std::size_t>(onset_cycle), v_onset, max_decel, travel_mm, w.world->max_penetration_mm());
  CHECK(v_onset == doctest::Approx(20.0).epsilon(0.01));
  CHECK(speed(static_cast<std::size_t>(onset_cycle)) < v_onset);  // slower in the onset's own cycle
  // The arm command's floats (arm.h) quantise the joint angles by up to 1.5e-7 rad: ~0.15 um at
  // the pad, 4 samples in a second difference, 600 mm/s^2 per cycle. A jump to rest from
  // 20 mm/s would be 20000 mm/s^2; the stop's mean deceleration is held to the limit.
  CHECK(max_decel <= 2000.0 + 600.0);
  const std::size_t stop_cycles = p.size() - static_cast<std::size_t>(onset_cycle);
  CHECK(stop_cycles >= 10);  // 20 mm/s at 2000 mm/s^2: 10 ms
  // v^2 / 2a, v a / 2j for the stop's jerk ramps (MotionParams' stop jerk), and one cycle.
  CHECK(travel_mm <= 20.0 * 20.0 / (2 * 2000.0) + 20.0 * 2000.0 / (2 * MotionParams{}.stop_jerk_mm_s3) + 0.03);
  // Held: the world's arm stays put.
  const KDL::Vector rest = w.pad_applied();
  for (int i = 0; i < 200; ++i) w.cycle();
  CHECK(1e3 * norm((w.pad_applied() - rest)) < 1e-6);
}

namespace {

// config/sim.yaml's contact_r parameters, its joints' test alone (the taxels read nothing below
// 0.35 N: plugins/contact_controller/README.md).
crease::contact::ContactConfig shipped_contact_r(const std::string& extra) {
  const YAML::Node root = YAML::LoadFile(std::string(CREASE_SOURCE_DIR) + "/config/sim.yaml");
  YAML::Node params;
  for (const auto& pl : root["plugins"])
    if (pl["name"].as<std::string>() == "contact_r") params = YAML::Clone(pl["params"]);
  REQUIRE(params.IsMap());
  params["tactile"] = "none";
  if (!extra.empty()) {
    const YAML::Node more = YAML::Load(extra);
    for (auto it = more.begin(); it != more.end(); ++it) params[it->first.as<std::string>()] = it->second;
  }
  return crease::contact::read_contact_config(crease::Params(params, "sim.yaml", "contact_r.params"));
}

}  // namespace

TEST_CASE("the chain on the world: contact_r's Eq. 5 on the world's hand angles stops the jerk-limited descent within 3 "
          "cycles of the first contact, <= 1 mm deep (failing variant: Delta theta_max 2 mrad)") {
  for (const bool shipped : {true, false}) {
    CAPTURE(shipped);
    WorldRig w;
    crease::contact::ContactDetector detector(shipped_contact_r(shipped ? "" : "{enter_rad: 0.002, exit_rad: 0.001}"));
    // Each cycle the detector sees the world's hand after the last step, quantised as on the wire.
    crease::HandState hs;
    hs.valid = (1u << 20) - 1;
    hs.fresh = 1;
    hs.health = DeviceHealth::ok;
    crease::HandCommand hc;
    for (int j = 0; j < robot::kHandJoints; ++j) hc.target_rad[j] = static_cast<float>(w.hand_target[j]);
    const auto sense = [&] {
      const auto& h = w.world->hand_angles(Side::right);
      for (int j = 0; j < robot::kHandJoints; ++j) hs.position_rad[j] = static_cast<float>(std::round(h[j] * 1e4) * 1e-4);
      hs.timestamp_ns = w.now + kPeriod;
      crease::contact::ContactInputs in;
      in.time_ns = hs.timestamp_ns;
      in.hand = &hs;
      in.hand_new = true;
      in.command = &hc;
      crease::ContactEvent ev;
      (void)detector.step_rt(in, w.contact, ev);
    };
    for (int i = 0; i < 100; ++i) {  // the detector arms on the still hand
      sense();
      w.cycle();
    }
    REQUIRE(w.contact.armed == 1);
    const KDL::Frame start(KDL::Rotation::RotX(-0.7) * w.pad().M, w.pad().p);
    ArmGoal above = goal_to(ToolFrame::ff_pad, KDL::Frame(start.M, KDL::Vector(start.p.x(), start.p.y(), 0.012)), 22, 80, 800);
    above.angular_speed_rad_s = 0.4f;
    sense();
    w.cycle(&above);
    while (w.active()) {
      sense();
      w.cycle();
    }
    REQUIRE(w.motion->status().state == ArmMotionStatus::reached);
    for (int i = 0; i < 100; ++i) {  // settled again at the new pose
      sense();
      w.cycle();
    }
    REQUIRE(w.contact.armed == 1);
    REQUIRE(w.contact.in_contact == 0);
    ArmGoal down = goal_to(ToolFrame::ff_pad, KDL::Frame(start.M, KDL::Vector(start.p.x(), start.p.y(), -0.005)), 23, 20, 200);
    down.stop_on = ArmGoal::contact_onset;
    down.stop_fingers = 0x1f;
    down.stop_accel_mm_s2 = 2000;
    sense();
    w.cycle(&down);
    long k = 0, first_touch = -1, onset = -1;
    double depth = 0, force_at_onset = 0;
    for (; k < 5000 && w.active(); ++k) {
      sense();
      if (onset < 0 && w.contact.in_contact != 0) {
        onset = k;
        for (const auto& t : w.world->state().hand[0].tip) force_at_onset += t.contact != 0 ? t.normal_force_n : 0.0;
      }
      w.cycle();
      bool touching = false;
      for (const auto& t : w.world->state().hand[0].tip) touching = touching || t.contact != 0;
      if (touching && first_touch < 0) first_touch = k;
      depth = std::max(depth, w.world->max_penetration_mm());
    }
    for (int i = 0; i < 300; ++i) {
      sense();
      w.cycle();
      depth = std::max(depth, w.world->max_penetration_mm());
    }
    double force_after = 0;
    for (const auto& t : w.world->state().hand[0].tip) force_after += t.contact != 0 ? t.normal_force_n : 0.0;
    REQUIRE(first_touch >= 0);
    REQUIRE(onset >= 0);
    const long latency = onset - first_touch;
    std::printf("chain (%s): detected %ld cycles after the world's first contact, %.4f N then, %.4f N at rest (all fingertips, "
                "1 N m/rad); "
                "worst depth %.4f mm; stopped %s\n",
                shipped ? "contact_r as shipped" : "2 mrad", latency, force_at_onset, force_after, depth,
                w.motion->status().state == ArmMotionStatus::stopped_on_contact ? "on contact" : "otherwise");
    CHECK(w.motion->status().state == ArmMotionStatus::stopped_on_contact);
    CHECK(depth <= 1.0);
    CHECK(latency >= 1);
    if (shipped) CHECK(latency <= 3);
    else CHECK(latency > 3);
  }
}
