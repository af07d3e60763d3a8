// The arm motion controller against an arm that follows its command: motions reach their
// targets within the goal's limits and are then held unchanged, via points are passed, a
// contact onset stops a motion in the same cycle with a deceleration inside the limits, every
// bad goal is refused with its counted reason while nothing moves, a stale or faulted arm
// aborts and holds, a motion carries across a hot-swap, and update allocates nothing. Poses
// are scored with robot_model's forward kinematics of the commanded angles.
#include "plugins/arm_motion/arm_motion.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "motion_rig.h"
#include "rt/alloc_guard.h"

using namespace rig;

namespace {

// Speeds and accelerations of the tool frame along the cycles (from FK of q_cmd).
struct Trace {
  std::vector<KDL::Frame> pose;
  [[nodiscard]] double speed_mm_s(std::size_t i) const { return i == 0 ? 0 : 1e6 * norm((pose[i].p - pose[i - 1].p)); }
  [[nodiscard]] double accel_mm_s2(std::size_t i) const {
    if (i < 2) return 0;
    const KDL::Vector v1 = pose[i].p - pose[i - 1].p, v0 = pose[i - 1].p - pose[i - 2].p;
    return 1e9 * norm((v1 - v0));
  }
  [[nodiscard]] double angular_speed(std::size_t i) const { return i == 0 ? 0 : 1e3 * rot_angle(pose[i - 1].M, pose[i].M); }
  [[nodiscard]] double max_speed() const {
    double m = 0;
    for (std::size_t i = 1; i < pose.size(); ++i) m = std::max(m, speed_mm_s(i));
    return m;
  }
  [[nodiscard]] double max_accel() const {
    double m = 0;
    for (std::size_t i = 2; i < pose.size(); ++i) m = std::max(m, accel_mm_s2(i));
    return m;
  }
};

void idle(Rig& r, int n = 5) {
  for (int i = 0; i < n; ++i) REQUIRE(r.cycle());
}

KDL::Frame shifted(const KDL::Frame& f, double dx_mm, double dy_mm, double dz_mm, const KDL::Rotation& turn = {}) {
  return KDL::Frame(turn * f.M, f.p + KDL::Vector(dx_mm, dy_mm, dz_mm) / 1000.0);
}

bool same_command(const ArmCommand& a, const ArmCommand& b) {
  return a.mode == b.mode && std::memcmp(a.position_rad, b.position_rad, sizeof(a.position_rad)) == 0 &&
         std::memcmp(a.velocity_rad_s, b.velocity_rad_s, sizeof(a.velocity_rad_s)) == 0;
}

}  // namespace

TEST_CASE("a motion reaches its target within the goal's limits; its final command is then held unchanged") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  const KDL::Frame target = shifted(start, 80, -50, -60, KDL::Rotation::RotZ(0.3) * KDL::Rotation::RotX(0.1));
  const ArmGoal g = goal_to(ToolFrame::ff_pad, target, 7, 100, 1000);
  Trace t;
  REQUIRE(r.cycle(&g));
  CHECK(r.motion->status().state == ArmMotionStatus::checking);
  CHECK(r.motion->status().goal_id == 7);
  int n = 0;
  while (r.active() && n++ < 20000) {
    r.cycle();
    t.pose.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)));
  }
  const ArmMotionStatus& st = r.motion->status();
  REQUIRE(st.state == ArmMotionStatus::reached);
  CHECK(st.progress == 1.0f);
  CHECK(st.distance_to_go_mm == 0.0f);
  CHECK(st.goals_accepted == 1);
  const KDL::Frame end = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  CHECK(mm(end.p - target.p) < 0.01);
  CHECK(1e3 * rot_angle(end.M, target.M) < 0.01);
  // Within the limits, every cycle (the path is straight: its acceleration is along it).
  CHECK(t.max_speed() <= 100.0 * 1.001);
  CHECK(t.max_speed() >= 99.0);  // and it did cruise at the speed asked
  CHECK(t.max_accel() <= 1000.0 * 1.01);
  double w = 0;
  for (std::size_t i = 1; i < t.pose.size(); ++i) w = std::max(w, t.angular_speed(i));
  CHECK(w <= 1.0 * 1.001);
  // Held: 3000 cycles later, the same command bit for bit.
  const ArmCommand final_cmd = r.last;
  for (int i = 0; i < 3000; ++i) {
    REQUIRE(r.cycle());
    REQUIRE(same_command(r.last, final_cmd));
  }
  for (float v : r.last.velocity_rad_s) CHECK(v == 0.0f);
  CHECK(r.motion->status().state == ArmMotionStatus::reached);
}

TEST_CASE(
    "the status says where the tool is by the arm's readings, every cycle of a motion; not without "
    "a reading") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  const ArmGoal g =
      goal_to(ToolFrame::ff_pad, shifted(start, 60, 40, -30, KDL::Rotation::Identity()), 3);
  REQUIRE(r.cycle(&g));
  int n = 0;
  double worst = 0, moved = 0;
  while (r.active() && n++ < 20000) {
    const Joints read = r.q_arm;  // what this cycle's arm_state reports (the last command)
    r.cycle();
    const ArmMotionStatus& st = r.motion->status();
    REQUIRE(st.tool_measured == 1);
    REQUIRE(st.tool == static_cast<std::uint8_t>(ToolFrame::ff_pad));
    const KDL::Frame at = r.tool_pose_at(ToolFrame::ff_pad, read);  // robot_model's FK
    const KDL::Vector got(st.tool_mm[0] / 1000.0, st.tool_mm[1] / 1000.0, st.tool_mm[2] / 1000.0);
    worst = std::max(worst, mm(got - at.p));
    moved = std::max(moved, mm(got - start.p));
  }
  CHECK(worst < 0.001);  // float mm
  CHECK(moved > 70.0);   // it followed the motion (78 mm)
  // No arm reading (a faulted state that is not finite): no position, the flag down.
  r.arm_fresh = false;
  r.q_arm[0] = std::numeric_limits<double>::quiet_NaN();
  r.cycle();
  CHECK(r.motion->status().tool_measured == 0);
}

TEST_CASE("via points are passed exactly, at rest, in order") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::palm_front, q_cmd(r));
  const KDL::Frame a = shifted(start, 40, 0, 0), b = shifted(start, 40, 40, -20), c = shifted(start, 0, 40, 0);
  ArmGoal g = goal_to(ToolFrame::palm_front, a, 2, 150, 1500);
  add_point(g, b);
  add_point(g, c);
  REQUIRE(r.cycle(&g));
  double closest[3] = {1e9, 1e9, 1e9};
  int segment_changes = 0, at_rest = 0;
  const KDL::Frame pts[3] = {a, b, c};
  std::uint8_t segment = 0;
  while (r.active()) {
    r.cycle();
    const KDL::Frame p = r.tool_pose_at(ToolFrame::palm_front, q_cmd(r));
    for (int k = 0; k < 3; ++k) closest[k] = std::min(closest[k], mm(p.p - pts[k].p));
    if (r.motion->status().segment != segment) {  // at via point `segment`, at rest
      CHECK(r.motion->status().segment == segment + 1);
      CHECK(mm(p.p - pts[segment].p) < 1e-3);
      at_rest += r.motion->status().speed_mm_s == 0.0f;
      segment = r.motion->status().segment;
      ++segment_changes;
    }
  }
  CHECK(r.motion->status().state == ArmMotionStatus::reached);
  CHECK(r.motion->status().reason == 0);
  for (double d : closest) CHECK(d < 1e-3);
  CHECK(segment_changes == 2);
  CHECK(at_rest == 2);
}

namespace {

// The third difference of three-dimensional samples (m/s^3 at 1 kHz).
double jerk_m_s3(const std::vector<KDL::Vector>& p, std::size_t i) {
  return i < 3 ? 0.0 : 1e9 * norm((p[i] - 3 * p[i - 1] + 3 * p[i - 2] - p[i - 3]));
}

}  // namespace

TEST_CASE("the Cartesian trajectory is jerk-limited over a whole motion with via points and a contact stop (failing "
          "variant: jerk_mm_s3 0, acceleration-limited)") {
  for (const bool jerk : {true, false}) {
    CAPTURE(jerk);
    MotionParams p = params();
    if (!jerk) p.jerk_mm_s3 = 0;
    Rig r(p);
    idle(r);
    const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
    ArmGoal g = goal_to(ToolFrame::ff_pad, shifted(start, 40, 0, 0), 1, 100, 1000);
    add_point(g, shifted(start, 40, 30, -20, KDL::Rotation::RotZ(0.3)));
    add_point(g, shifted(start, 40, 30, -80, KDL::Rotation::RotZ(0.3)));
    g.stop_on = ArmGoal::contact_onset;
    g.stop_fingers = 0x01;
    REQUIRE(r.cycle(&g));
    // The path's commanded pose each cycle (what the IK tracks) and the FK of the commanded angles.
    std::vector<KDL::Vector> path, fk;
    const auto sample = [&] {
      const MotionState& st = r.motion->state();
      path.push_back(pose_at(st.path, st.profile.segment, st.profile.sigma).p);
      fk.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)).p);
    };
    for (int i = 0; i < 3; ++i) sample();
    int n = 0;
    std::size_t stop_at = 0;  // the first sample of the stop
    while (r.active() && n++ < 20000) {
      if (r.motion->state().profile.segment == 2 && r.motion->state().profile.sigma > 0.5 && r.contact.onsets == 0) {
        r.contact.onsets = 1;  // the index finger touches half way down the last segment
        r.contact.fingers = 0x01;
        r.contact.in_contact = 1;
      }
      r.cycle();
      sample();
      if (stop_at == 0 && r.motion->status().state == ArmMotionStatus::stopping) stop_at = path.size() - 1;
    }
    for (int i = 0; i < 3; ++i) {
      r.cycle();
      sample();
    }
    REQUIRE(r.motion->status().state == ArmMotionStatus::stopped_on_contact);
    REQUIRE(stop_at > 0);
    double path_jerk = 0, fk_jerk = 0, motion_jerk = 0;
    for (std::size_t i = 3; i < path.size(); ++i) {
      path_jerk = std::max(path_jerk, jerk_m_s3(path, i));
      fk_jerk = std::max(fk_jerk, jerk_m_s3(fk, i));
      if (i < stop_at) motion_jerk = std::max(motion_jerk, jerk_m_s3(path, i));
    }
    MESSAGE(std::string(jerk ? "jerk-limited" : "acceleration-limited") << ": the path's jerk at most " << path_jerk
            << " m/s^3 (the commanded angles' FK: " << fk_jerk << " m/s^3), over " << path.size() << " cycles");
    if (jerk) {
      // The motion's jerk limit before the stop, the stop's from it (MotionParams' defaults:
      // 20 m/s^3 and 1000 m/s^3).
      CHECK(motion_jerk <= 1e-3 * p.jerk_mm_s3 * (1 + 1e-6));
      CHECK(motion_jerk >= 0.95e-3 * p.jerk_mm_s3);
      CHECK(path_jerk <= 1e-3 * p.stop_jerk_mm_s3 * (1 + 1e-6));
    } else {
      CHECK(path_jerk > 10e-3 * MotionParams{}.jerk_mm_s3);  // the acceleration's steps: a / dt (1000 m/s^3 and more)
    }
  }
}

TEST_CASE("a contact onset stops the motion in the same cycle, decelerating within the stop limit") {
  // The variant without a stop condition, the same onset: the motion goes on and reaches.
  for (const bool armed : {true, false}) {
    CAPTURE(armed);
    Rig r;
    idle(r);
    const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
    ArmGoal g = goal_to(ToolFrame::ff_pad, shifted(start, 0, 0, -60), 3, 50, 500);
    g.stop_on = armed ? ArmGoal::contact_onset : ArmGoal::stop_none;
    g.stop_accel_mm_s2 = 1000;
    g.stop_fingers = 0x01;  // the index finger
    REQUIRE(r.cycle(&g));
    Trace t;
    for (int i = 0; i < 600; ++i) {  // cruising at 50 mm/s by then
      r.cycle();
      t.pose.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)));
    }
    REQUIRE(r.motion->status().state == ArmMotionStatus::running);
    const double v_before = t.speed_mm_s(t.pose.size() - 1);
    REQUIRE(v_before == doctest::Approx(50.0).epsilon(1e-3));
    // An onset on the middle finger only: not one the goal stops on.
    r.contact.onsets = 1;
    r.contact.fingers = 0x02;
    r.contact.in_contact = 1;
    for (int i = 0; i < 3; ++i) {
      r.cycle();
      t.pose.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)));
    }
    CHECK(t.speed_mm_s(t.pose.size() - 1) == doctest::Approx(50.0).epsilon(1e-3));
    // The index finger's onset.
    r.contact.onsets = 2;
    r.contact.fingers = 0x03;
    const KDL::Vector at_onset = t.pose.back().p;
    r.cycle();
    t.pose.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)));
    const std::size_t onset = t.pose.size() - 1;
    if (!armed) {
      CHECK(t.speed_mm_s(onset) == doctest::Approx(50.0).epsilon(1e-3));
      r.run_to_end();
      CHECK(r.motion->status().state == ArmMotionStatus::reached);
      continue;
    }
    CHECK(r.motion->status().state == ArmMotionStatus::stopping);
    // This very cycle's command is slower: jerk-limited, by j dt^2 / 6 over the cycle (the
    // stop's jerk, MotionParams' 1000 m/s^3: 0.17 mm/s), then ever more.
    CHECK(t.speed_mm_s(onset) < v_before - 0.1);
    while (r.active()) {
      r.cycle();
      t.pose.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)));
    }
    CHECK(r.motion->status().state == ArmMotionStatus::stopped_on_contact);
    double max_decel = 0;
    for (std::size_t i = onset; i < t.pose.size(); ++i) max_decel = std::max(max_decel, t.accel_mm_s2(i));
    CHECK(max_decel <= 1000.0 * 1.01);  // a deceleration, not a jump
    CHECK(max_decel >= 900.0);          // at the stop limit asked
    // Stopped within v^2 / 2a (1.25 mm) of the onset's position, plus one cycle.
    CHECK(mm(t.pose.back().p - at_onset) <= 50.0 * 50.0 / (2 * 1000.0) + 0.05 + 1e-6);
    const ArmCommand held = r.last;
    for (int i = 0; i < 500; ++i) {
      r.cycle();
      REQUIRE(same_command(r.last, held));
    }
  }
}

// The contact detector can hold a contact with no new onset: a trial's fixing hand, lifted off
// the table after pressing, read lf and th in contact (its joints off their reference in the new
// pose), so the refixating descent's index touch raised no onset and the descent went to its depth
// (abort no_contact). A stop finger joining the held contact is the touch; stop fingers already in
// it at the start are not (the variant: the index held from the start goes on).
TEST_CASE(
    "a descent begun while other fingers hold a contact stops when a stop finger joins it, not on "
    "fingers held from the start") {
  for (const bool index_held : {false, true}) {
    CAPTURE(index_held);
    Rig r;
    r.contact.onsets = 1;
    r.contact.in_contact = 1;
    r.contact.fingers = index_held ? 0x19 : 0x18;  // lf and th (and the index)
    idle(r);
    const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
    ArmGoal g = goal_to(ToolFrame::ff_pad, shifted(start, 0, 0, -60), 3, 50, 500);
    g.stop_on = ArmGoal::contact_onset;
    g.stop_accel_mm_s2 = 1000;
    g.stop_fingers = 0x01;  // the index finger
    REQUIRE(r.cycle(&g));
    for (int i = 0; i < 300; ++i) r.cycle();
    REQUIRE(r.motion->status().state == ArmMotionStatus::running);
    r.contact.fingers = index_held ? 0x11 : 0x10;  // lf leaves the set: not a touch of the index
    for (int i = 0; i < 3; ++i) r.cycle();
    REQUIRE(r.motion->status().state == ArmMotionStatus::running);
    r.contact.fingers = 0x11;  // the index in the held contact, no new onset
    r.cycle();
    if (index_held) {
      CHECK(r.motion->status().state == ArmMotionStatus::running);
      // Released, then a new onset with the index: that stops it as always.
      r.contact.in_contact = 0;
      r.contact.fingers = 0;
      r.cycle();
      CHECK(r.motion->status().state == ArmMotionStatus::running);
      r.contact.in_contact = 1;
      r.contact.fingers = 0x01;
      r.contact.onsets = 2;
      r.cycle();
    }
    CHECK(r.motion->status().state == ArmMotionStatus::stopping);
    r.run_to_end();
    CHECK(r.motion->status().state == ArmMotionStatus::stopped_on_contact);
  }
}

TEST_CASE("bad goals are refused with a counted reason and nothing moves") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  const ArmGoal good = goal_to(ToolFrame::ff_pad, shifted(start, 30, 0, 0), 10);
  const Joints q0 = q_cmd(r);
  std::uint32_t id = 100;
  auto refused = [&](ArmGoal g, ArmMotionReason why, auto&& setup) {
    CAPTURE(static_cast<int>(why));
    g.id = ++id;
    const std::uint32_t before = r.motion->status().reasons[static_cast<int>(why)];
    setup();
    REQUIRE(r.cycle(&g));
    // The path is solved ahead check_samples_per_cycle samples a cycle: a long one takes a while.
    for (int i = 0; i < 2000 && r.motion->status().state == ArmMotionStatus::checking; ++i) r.cycle();
    const ArmMotionStatus& st = r.motion->status();
    CHECK(st.reasons[static_cast<int>(why)] == before + 1);
    CHECK(st.last_refused_id == id);
    CHECK(st.last_refusal == static_cast<std::uint8_t>(why));
    CHECK(st.goal_id == id);
    const bool unreachable = why == ArmMotionReason::unreachable || why == ArmMotionReason::joint_speed;
    CHECK(st.state == (unreachable ? ArmMotionStatus::unreachable : ArmMotionStatus::refused));
    CHECK(q_cmd(r) == q0);  // nothing moved
  };
  const auto nothing = [] {};
  ArmGoal g = good;
  g.position_mm[0][1] = NAN;
  refused(g, ArmMotionReason::non_finite, nothing);
  g = good;
  g.speed_mm_s = INFINITY;
  refused(g, ArmMotionReason::non_finite, nothing);
  g = good;
  for (double& x : g.orientation[0]) x *= 1.01;  // |q| = 1.01
  refused(g, ArmMotionReason::bad_orientation, nothing);
  g = good;
  g.tool = robot::kToolFrames;
  refused(g, ArmMotionReason::unknown_tool, nothing);
  g = good;
  g.point_count = 0;
  refused(g, ArmMotionReason::bad_points, nothing);
  g.point_count = ArmGoal::kMaxPoints + 1;
  refused(g, ArmMotionReason::bad_points, nothing);
  g = good;
  g.frame = 7;
  refused(g, ArmMotionReason::bad_points, nothing);
  g = good;
  g.speed_mm_s = 251;  // above max_speed_mm_s (250)
  refused(g, ArmMotionReason::bad_limits, nothing);
  g = good;
  g.accel_mm_s2 = 0;
  refused(g, ArmMotionReason::bad_limits, nothing);
  g = good;
  g.stop_accel_mm_s2 = g.accel_mm_s2 / 2;
  refused(g, ArmMotionReason::bad_limits, nothing);
  g = good;
  g.position_mm[0][2] = -50;  // below the table: outside the workspace box
  refused(g, ArmMotionReason::outside_workspace, nothing);
  g = good;
  g.frame = ArmGoal::sheet;  // no sheet_state
  refused(g, ArmMotionReason::no_sheet, nothing);
  g = good;
  g.stop_on = ArmGoal::contact_onset;
  refused(g, ArmMotionReason::no_contact_state, [&] { r.contact.healthy = 0; });
  r.contact.healthy = 1;
  refused(good, ArmMotionReason::arm_not_ready, [&] { r.drive_state = 7; });
  r.drive_state = 4;
  idle(r);
  // A target 1.75 m from the shoulder, inside the workspace box: no IK solution.
  g = goal_to(ToolFrame::ff_pad, KDL::Frame(start.M, KDL::Vector(-0.69, 0.59, 0.0)));
  refused(g, ArmMotionReason::unreachable, nothing);
  // A reachable target behind an unreachable via point: refused before anything moves.
  g = goal_to(ToolFrame::ff_pad, KDL::Frame(start.M, KDL::Vector(-0.69, 0.59, 0.0)));
  add_point(g, shifted(start, 30, 0, 0));
  refused(g, ArmMotionReason::unreachable, nothing);
  // Busy: a second goal while one runs is refused; the first goes on and reaches.
  ArmGoal first = good;
  first.id = 1000;
  REQUIRE(r.cycle(&first));
  for (int i = 0; i < 50; ++i) r.cycle();
  ArmGoal second = good;
  second.id = 1001;
  REQUIRE(r.cycle(&second));
  CHECK(r.motion->status().goal_id == 1000);
  CHECK(r.motion->status().state == ArmMotionStatus::running);
  CHECK(r.motion->status().last_refused_id == 1001);
  CHECK(r.motion->status().reasons[static_cast<int>(ArmMotionReason::busy)] == 1);
  r.run_to_end();
  CHECK(r.motion->status().state == ArmMotionStatus::reached);
}

TEST_CASE("a hand tool frame needs a fresh hand_state; a path faster than the joints allow is refused") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  const ArmGoal pad = goal_to(ToolFrame::ff_pad, shifted(start, 30, 0, 0), 5);
  r.hand_present = false;  // never written
  REQUIRE(r.cycle(&pad));
  CHECK(r.motion->status().state == ArmMotionStatus::refused);
  CHECK(r.motion->status().reason == static_cast<std::uint8_t>(ArmMotionReason::no_hand_state));
  r.hand_present = true;
  // The flange needs no hand.
  const ArmGoal fl = goal_to(ToolFrame::flange, shifted(r.tool_pose_at(ToolFrame::flange, q_cmd(r)), 30, 0, 0), 6);
  r.hand_present = false;
  REQUIRE(r.cycle(&fl));
  CHECK(r.motion->status().state == ArmMotionStatus::checking);
  r.run_to_end();
  CHECK(r.motion->status().state == ArmMotionStatus::reached);

  MotionParams slow = params();
  slow.joint_speed_fraction = 0.01;  // 1.8 deg/s: 100 mm/s needs more
  Rig s(slow);
  idle(s);
  const ArmGoal fast = goal_to(ToolFrame::ff_pad, shifted(s.tool_pose_at(ToolFrame::ff_pad, q_cmd(s)), 60, 0, 0), 8);
  const Joints q0 = q_cmd(s);
  REQUIRE(s.cycle(&fast));
  s.run_to_end();
  CHECK(s.motion->status().state == ArmMotionStatus::unreachable);
  CHECK(s.motion->status().reason == static_cast<std::uint8_t>(ArmMotionReason::joint_speed));
  CHECK(q_cmd(s) == q0);
}

TEST_CASE("a stale or faulted arm_state aborts the motion and holds; ready again, the hold is re-seated") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  const ArmGoal g = goal_to(ToolFrame::ff_pad, shifted(start, 60, 0, 0), 4);
  REQUIRE(r.cycle(&g));
  for (int i = 0; i < 200; ++i) r.cycle();
  REQUIRE(r.motion->status().state == ArmMotionStatus::running);
  r.arm_fresh = false;  // the status stops arriving
  int cycles = 0;
  while (r.motion->status().state == ArmMotionStatus::running && cycles < 100) {
    r.cycle();
    ++cycles;
  }
  CHECK(r.motion->status().state == ArmMotionStatus::aborted);
  CHECK(r.motion->status().reason == static_cast<std::uint8_t>(ArmMotionReason::arm_stale));
  CHECK(cycles == 6);  // older than arm_state_max_age_ms (5 ms)
  const ArmCommand held = r.last;
  for (int i = 0; i < 100; ++i) {
    r.cycle();
    REQUIRE(same_command(r.last, held));
  }
  for (float v : held.velocity_rad_s) CHECK(v == 0.0f);

  // A drive fault mid-motion: aborted in that cycle; the arm comes to rest elsewhere; when the
  // drive is enabled again the held command is where the arm is.
  r.arm_fresh = true;
  idle(r);
  const ArmGoal g2 = goal_to(ToolFrame::ff_pad, shifted(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)), 0, 50, 0), 5);
  REQUIRE(r.cycle(&g2));
  for (int i = 0; i < 200; ++i) r.cycle();
  REQUIRE(r.motion->status().state == ArmMotionStatus::running);
  r.drive_state = 7;
  r.follow = false;
  r.cycle();
  CHECK(r.motion->status().state == ArmMotionStatus::aborted);
  CHECK(r.motion->status().reason == static_cast<std::uint8_t>(ArmMotionReason::arm_fault));
  CHECK(r.motion->status().reasons[static_cast<int>(ArmMotionReason::arm_fault)] == 1);
  for (double& q : r.q_arm) q += 0.01;  // quick stop: the arm halted a little further on
  r.cycle();
  r.drive_state = 4;
  r.cycle();
  for (int j = 0; j < robot::kArmJoints; ++j) CHECK(r.last.position_rad[j] == static_cast<float>(r.q_arm[j]));
}

TEST_CASE("a stale contact_state while the stop condition is armed decelerates and aborts; a stop goal too") {
  for (const bool stop_goal : {false, true}) {
    CAPTURE(stop_goal);
    Rig r;
    idle(r);
    ArmGoal g = goal_to(ToolFrame::ff_pad, shifted(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)), 0, 0, -60), 9, 50, 500);
    g.stop_on = ArmGoal::contact_onset;
    REQUIRE(r.cycle(&g));
    for (int i = 0; i < 400; ++i) r.cycle();
    REQUIRE(r.motion->status().state == ArmMotionStatus::running);
    ArmGoal stop;
    stop.kind = ArmGoal::stop;
    if (stop_goal) {
      r.cycle(&stop);
    } else {
      r.contact_fresh = false;
      for (int i = 0; i < 7; ++i) r.cycle();
    }
    CHECK(r.motion->status().state == ArmMotionStatus::stopping);
    r.run_to_end();
    CHECK(r.motion->status().state == ArmMotionStatus::aborted);
    CHECK(r.motion->status().reason ==
          static_cast<std::uint8_t>(stop_goal ? ArmMotionReason::stopped : ArmMotionReason::contact_stale));
  }
}

// The hand's command stage lets go (force_controller retreats, or stops adding force, or its
// status goes stale): the arm must not drag the hand on. Failing variant: the same events with
// the status not watched (no hand_control_status port) change nothing and the motion reaches.
TEST_CASE("the hand's controller retreating, inhibited or stale stops a running motion, decelerating, and refuses goals") {
  enum Event { retreat, inhibit, stale };
  for (const Event e : {retreat, inhibit, stale}) {
    for (const bool watched : {true, false}) {
      CAPTURE(static_cast<int>(e));
      CAPTURE(watched);
      Rig r;
      r.hand_control_present = watched;
      idle(r);
      ArmGoal g = goal_to(ToolFrame::ff_pad, shifted(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)), 0, 0, -60), 11, 50, 500);
      REQUIRE(r.cycle(&g));  // no stop condition: only the hand's state can stop it
      Trace t;
      for (int i = 0; i < 600; ++i) {
        r.cycle();
        t.pose.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)));
      }
      REQUIRE(r.motion->status().state == ArmMotionStatus::running);
      const double v_before = t.speed_mm_s(t.pose.size() - 1);
      if (e == retreat) r.hand_control.mode = HandMode::retreat;
      if (e == inhibit) r.hand_control.inhibit = HandInhibit::hand_state_stale;
      if (e == stale) r.hand_control_fresh = false;
      // Stale: once older than hand_state_max_age_s (20 ms).
      const int cycles = e == stale ? 21 : 1;
      for (int i = 0; i < cycles; ++i) {
        r.cycle();
        t.pose.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)));
      }
      const std::size_t fired = t.pose.size() - 1;
      if (!watched) {
        CHECK(r.motion->status().state == ArmMotionStatus::running);
        r.run_to_end();
        CHECK(r.motion->status().state == ArmMotionStatus::reached);
        continue;
      }
      CHECK(r.motion->status().state == ArmMotionStatus::stopping);
      CHECK(t.speed_mm_s(fired) < v_before - 0.1);  // slower in the cycle it saw it
      while (r.active()) {
        r.cycle();
        t.pose.push_back(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)));
      }
      CHECK(r.motion->status().state == ArmMotionStatus::aborted);
      CHECK(r.motion->status().reason == static_cast<std::uint8_t>(ArmMotionReason::hand_retreat));
      CHECK(r.motion->status().reasons[static_cast<int>(ArmMotionReason::hand_retreat)] == 1);
      double max_decel = 0;
      for (std::size_t i = fired; i < t.pose.size(); ++i) max_decel = std::max(max_decel, t.accel_mm_s2(i));
      CHECK(max_decel <= 1000.0 * 1.01);  // the goal's stop deceleration, not a jump
      // While the hand is still letting go, a new goal pressing on is refused and nothing moves
      // (a lift goes: arm_motion_lift_test.cpp).
      const ArmCommand held = r.last;
      ArmGoal again = goal_to(ToolFrame::ff_pad, shifted(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)), 0, 0, -10), 12, 50, 500);
      r.cycle(&again);
      CHECK(r.motion->status().last_refused_id == 12);
      CHECK(r.motion->status().last_refusal == static_cast<std::uint8_t>(ArmMotionReason::hand_retreat));
      for (int i = 0; i < 100; ++i) {
        r.cycle();
        REQUIRE(same_command(r.last, held));
      }
    }
  }
}

TEST_CASE("a sheet-frame goal's points are taken relative to the sheet frame given at its start") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  // A sheet frame turned 90 deg about z, somewhere near the start.
  const KDL::Frame sheet(KDL::Rotation::RotZ(1.5707963267948966), start.p + KDL::Vector(0.02, 0.01, 0));
  const KDL::Frame local = sheet.Inverse() * shifted(start, 20, 30, -10);
  ArmGoal g = goal_to(ToolFrame::ff_pad, local, 11);
  g.frame = ArmGoal::sheet;
  r.sheet_frame = &sheet;
  REQUIRE(r.cycle(&g));
  r.sheet_frame = nullptr;
  r.run_to_end();
  REQUIRE(r.motion->status().state == ArmMotionStatus::reached);
  CHECK(mm(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)).p - shifted(start, 20, 30, -10).p) < 0.01);
}

TEST_CASE("a measured-frame goal moves the tool from where the arm is measured, not from where it is commanded") {
  Rig r;
  idle(r);
  // A drive that lags its command (as one stopped on its way would): the arm measured 10 mrad
  // behind on the shoulder and elbow joints, held there.
  r.follow = false;
  r.q_arm[0] += 0.01;
  r.q_arm[3] -= 0.01;
  idle(r, 2);
  Joints measured{};
  for (int j = 0; j < robot::kArmJoints; ++j) measured[j] = static_cast<float>(r.q_arm[j]);  // as arm_state carries it
  const KDL::Frame here = r.tool_pose_at(ToolFrame::ff_pad, measured);
  const KDL::Frame commanded = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  MESSAGE("measured vs commanded tool frame: " << mm(here.p - commanded.p) << " mm apart");
  REQUIRE(mm(here.p - commanded.p) > 3.0);
  const KDL::Frame lifted = shifted(here, 0, 0, 30);  // 30 mm straight up from where it is
  ArmGoal lift = goal_to(ToolFrame::ff_pad, KDL::Frame::Identity(), 21);
  lift.frame = ArmGoal::measured;
  lift.position_mm[0][2] = 30.0;
  bool old_way = false;
  SUBCASE("measured: an offset from the measured pose") {}
  SUBCASE("failing variant: the same lift from the commanded pose (a world goal 30 mm above it)") {
    old_way = true;
    lift = goal_to(ToolFrame::ff_pad, shifted(commanded, 0, 0, 30), 21);
  }
  REQUIRE(r.cycle(&lift));
  r.run_to_end();
  REQUIRE(r.motion->status().state == ArmMotionStatus::reached);
  const KDL::Frame end = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  if (old_way) {
    CHECK(mm(end.p - lifted.p) > 3.0);
    return;
  }
  CHECK(mm(end.p - lifted.p) < 0.01);
  CHECK(rot_angle(end.M, here.M) < 1e-5);  // the orientation kept
  // Offsets leaving the workspace are refused as any point would be; nothing moves.
  const Joints q0 = q_cmd(r);
  ArmGoal far = lift;
  far.id = 22;
  far.position_mm[0][2] = 5000.0;
  REQUIRE(r.cycle(&far));
  CHECK(r.motion->status().last_refused_id == 22);
  CHECK(r.motion->status().last_refusal == static_cast<std::uint8_t>(ArmMotionReason::outside_workspace));
  CHECK(q_cmd(r) == q0);
}

TEST_CASE("hot-swap: a motion saved mid-way and loaded into a new controller goes on bit for bit") {
  Rig a, b;
  idle(a);
  idle(b);
  const ArmGoal g = goal_to(ToolFrame::mf_pad, shifted(a.tool_pose_at(ToolFrame::mf_pad, q_cmd(a)), 50, -30, 20,
                                                       KDL::Rotation::RotY(0.2)), 12);
  REQUIRE(a.cycle(&g));
  for (int i = 0; i < 300; ++i) a.cycle();
  REQUIRE(a.motion->status().state == ArmMotionStatus::running);
  std::vector<std::byte> bytes(sizeof(MotionState) + 64);
  const std::size_t n = a.motion->save_state(bytes);
  REQUIRE(n == sizeof(MotionState));
  CHECK(a.motion->save_state(std::span<std::byte>(bytes.data(), n - 1)) == SIZE_MAX);
  CHECK_FALSE(b.motion->load_state(std::span<const std::byte>(bytes.data(), n - 1)));
  std::vector<std::byte> bad(bytes.begin(), bytes.begin() + static_cast<long>(n));
  bad[0] = std::byte{0};
  CHECK_FALSE(b.motion->load_state(bad));
  REQUIRE(b.motion->load_state(std::span<const std::byte>(bytes.data(), n)));
  b.q_arm = a.q_arm;
  b.now = a.now;
  int cycles = 0;
  while (a.active()) {
    a.cycle();
    b.cycle();
    REQUIRE(same_command(a.last, b.last));
    ++cycles;
  }
  CHECK(cycles > 100);
  CHECK(b.motion->status().state == ArmMotionStatus::reached);
  CHECK(b.motion->status().goal_id == 12);
}

TEST_CASE("steady state allocates nothing: holding, a goal arriving, checking, running, stopping") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  ArmGoal g = goal_to(ToolFrame::ff_pad, shifted(start, 40, 20, -30), 13);
  add_point(g, shifted(start, 0, 0, -30));
  g.stop_on = ArmGoal::contact_onset;
  ArmGoal bad = g;
  bad.position_mm[0][0] = NAN;
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    for (int i = 0; i < 100; ++i) r.cycle();
    r.cycle(&bad);
    r.cycle(&g);
    for (int i = 0; i < 500; ++i) r.cycle();
    r.contact.onsets = 1;
    r.contact.fingers = 1;
    r.run_to_end();
    for (int i = 0; i < 100; ++i) r.cycle();
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(r.motion->status().state == ArmMotionStatus::stopped_on_contact);
}
