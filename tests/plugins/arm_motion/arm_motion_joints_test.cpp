// arm_motion's joints goals (ArmGoal::joints): the retreat to a parking pose from a pose whose
// straight line there the arm cannot follow. The pose is solved once on arrival (seeded from
// where the arm started) and every joint runs one quintic profile to it: within the joint
// limits and the speed and acceleration limits every cycle, at rest at the end, the tool at the
// pose; a stop decelerates it; a pose out of reach is refused on arrival; nothing allocates.
#include "plugins/arm_motion/arm_motion.h"

#include <doctest/doctest.h>

#include <cmath>

#include "motion_rig.h"
#include "rt/alloc_guard.h"

using namespace rig;

namespace {

void idle(Rig& r, int n = 5) {
  for (int i = 0; i < n; ++i) r.cycle();
}

// The start pose turned by ANGLE about the world's vertical through the tool and raised: the
// wrist's turn a bend leaves a parking move to undo.
KDL::Frame turned(const KDL::Frame& start, double angle_rad, double up_mm) {
  return KDL::Frame(KDL::Rotation::RotZ(angle_rad) * start.M, start.p + KDL::Vector(0, 0, up_mm / 1000.0));
}

ArmGoal joints_goal(const KDL::Frame& pose, std::uint32_t id) {
  ArmGoal g = goal_to(ToolFrame::ff_pad, pose, id, 60, 300);
  g.interpolation = ArmGoal::joints;
  return g;
}

}  // namespace

TEST_CASE("a joints goal reaches a pose whose straight line the arm cannot follow, within every limit, at rest") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  const KDL::Frame target = turned(start, 2.4, 0);  // from the start posture: the line is refused, the pose is not
  // Failing variant: the same pose as a Cartesian goal is refused (the wrist's turn on the line).
  {
    Rig c;
    idle(c);
    c.cycle(&static_cast<const ArmGoal&>(goal_to(ToolFrame::ff_pad, target, 7, 60, 300)));
    c.run_to_end();
    const auto st = c.motion->status();
    CHECK((st.state == ArmMotionStatus::unreachable || st.state == ArmMotionStatus::refused));
  }
  const ArmGoal g = joints_goal(target, 8);
  r.cycle(&g);
  CHECK(r.motion->status().state == ArmMotionStatus::running);  // nothing to check ahead
  const auto& ik = r.motion->ik();
  const MotionParams p = params();
  Joints prev = q_cmd(r);
  double prev_v[robot::kArmJoints] = {};
  int cycles = 0, over_speed = 0, over_accel = 0, outside = 0;
  while (r.active() && cycles < 60000) {
    r.cycle();
    ++cycles;
    const Joints q = q_cmd(r);
    for (int j = 0; j < robot::kArmJoints; ++j) {
      const double v = (q[j] - prev[j]) / 1e-3;
      over_speed += std::abs(v) > p.joint_speed_fraction * ik.velocity_limit()[j] * 1.001;
      over_accel += std::abs(v - prev_v[j]) / 1e-3 > p.joint_accel_rad_s2 * 1.01 + 1e-6;
      outside += q[j] < ik.lower()[j] - 1e-9 || q[j] > ik.upper()[j] + 1e-9;
      prev_v[j] = v;
    }
    prev = q;
  }
  CHECK(r.motion->status().state == ArmMotionStatus::reached);
  CHECK(r.motion->status().goal_id == 8);
  CHECK(over_speed == 0);
  CHECK(over_accel == 0);
  CHECK(outside == 0);
  for (double v : r.motion->state().v_cmd) CHECK(v == 0.0);
  const KDL::Frame end = r.tool_pose(ToolFrame::ff_pad);
  CHECK(mm(end.p - target.p) < 0.1);
  CHECK(rot_angle(end.M, target.M) < 1e-3);
  // Held there afterwards.
  const Joints held = q_cmd(r);
  idle(r, 100);
  CHECK(q_cmd(r) == held);
}

TEST_CASE("a stop decelerates a joints goal within the acceleration limit and ends it aborted; a pose out of reach is refused") {
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  const ArmGoal g = joints_goal(turned(start, 2.4, 0), 9);
  r.cycle(&g);
  for (int i = 0; i < 800; ++i) r.cycle();
  ArmGoal stop;
  stop.kind = ArmGoal::stop;
  Joints prev = q_cmd(r);
  double prev_v[robot::kArmJoints];
  for (int j = 0; j < robot::kArmJoints; ++j) prev_v[j] = r.motion->state().v_cmd[j];
  int cycles = 0, over_accel = 0;
  while ((cycles == 0 || r.active()) && cycles < 20000) {
    r.cycle(cycles == 0 ? &stop : nullptr);
    ++cycles;
    const Joints q = q_cmd(r);
    for (int j = 0; j < robot::kArmJoints; ++j) {
      const double v = (q[j] - prev[j]) / 1e-3;
      over_accel += std::abs(v - prev_v[j]) / 1e-3 > params().joint_accel_rad_s2 * 1.01 + 1e-6;
      prev_v[j] = v;
    }
    prev = q;
  }
  CHECK(cycles > 10);  // it was moving: not a jump to rest
  CHECK(over_accel == 0);
  CHECK(r.motion->status().state == ArmMotionStatus::aborted);
  CHECK(r.motion->status().reason == static_cast<std::uint8_t>(ArmMotionReason::stopped));

  const std::uint64_t refused = r.motion->status().goals_refused;
  r.cycle(&static_cast<const ArmGoal&>(joints_goal(KDL::Frame(start.M, start.p + KDL::Vector(0, 0, 3.0)), 10)));  // 3 m up
  CHECK(r.motion->status().goals_refused == refused + 1);
  CHECK(r.motion->status().last_refused_id == 10);
}

TEST_CASE("a joints goal allocates nothing: arriving, running, stopping") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  Rig r;
  idle(r);
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  const ArmGoal g = joints_goal(turned(start, 1.0, 40), 11);
  ArmGoal stop;
  stop.kind = ArmGoal::stop;
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    r.cycle(&g);
    for (int i = 0; i < 300; ++i) r.cycle();
    r.cycle(&stop);
    r.run_to_end();
  }
  CHECK(crease::rt::rt_allocation_count() == before);
}
