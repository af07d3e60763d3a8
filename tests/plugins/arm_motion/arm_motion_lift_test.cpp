// arm_motion while the hand's controller retreats (force_controller's latched force-limit
// retreat, an inhibit): a lift (path_is_lift, goal_check.h) is the safe direction and goes;
// a press or any other motion stays refused (and a running one aborted).
#include "plugins/arm_motion/arm_motion.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstring>

#include "motion_rig.h"
#include "rt/alloc_guard.h"

using namespace rig;

namespace {

KDL::Frame shifted(const KDL::Frame& f, double dx_mm, double dy_mm, double dz_mm, const KDL::Rotation& turn = {}) {
  return KDL::Frame(turn * f.M, f.p + KDL::Vector(dx_mm, dy_mm, dz_mm) / 1000.0);
}

// The fold sequence's abort lift: 30 mm straight up from where the tool is measured, the
// orientation kept (fold_sequence's arm_lift).
ArmGoal measured_lift(std::uint32_t id, double up_mm) {
  ArmGoal g = goal_to(ToolFrame::ff_pad, KDL::Frame::Identity(), id, 50, 500);
  g.frame = ArmGoal::measured;
  g.position_mm[0][2] = up_mm;
  return g;
}

}  // namespace

// A press aborted by the hand's retreat (the hand pressed over its force limit), then the
// abort's lift. Failing variant: the same lift turned 0.2 rad about the pad's x (not a lift:
// the rest of the hand could swing down) is refused like any motion and the pad stays on the
// sheet, as every goal was under the old rule.
TEST_CASE("while the hand retreats a lift straight up goes; a press, a sideways move or a turn stays refused") {
  bool turned = false;
  SUBCASE("the lift") {}
  SUBCASE("failing variant: the lift with a turn") { turned = true; }
  Rig r;
  for (int i = 0; i < 5; ++i) REQUIRE(r.cycle());
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  ArmGoal press = goal_to(ToolFrame::ff_pad, shifted(start, 0, 0, -60), 1, 50, 500);
  REQUIRE(r.cycle(&press));
  for (int i = 0; i < 600; ++i) r.cycle();
  REQUIRE(r.motion->status().state == ArmMotionStatus::running);
  r.hand_control.mode = HandMode::retreat;  // a fingertip over force_limit_n: latched
  r.hand_control.inhibit = HandInhibit::force_limit;
  r.run_to_end();
  REQUIRE(r.motion->status().state == ArmMotionStatus::aborted);
  REQUIRE(r.motion->status().reason == static_cast<std::uint8_t>(ArmMotionReason::hand_retreat));
  const KDL::Frame low = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));

  // Pressing further, moving sideways, or down and then up: refused, nothing moves.
  const Joints held = q_cmd(r);
  ArmGoal deeper = goal_to(ToolFrame::ff_pad, shifted(low, 0, 0, -10), 2, 50, 500);
  ArmGoal aside = goal_to(ToolFrame::ff_pad, shifted(low, 30, 0, 5), 3, 50, 500);
  ArmGoal dip = goal_to(ToolFrame::ff_pad, shifted(low, 0, 0, -5), 4, 50, 500);
  add_point(dip, shifted(low, 0, 0, 30));
  for (ArmGoal* g : {&deeper, &aside, &dip}) {
    CAPTURE(g->id);
    REQUIRE(r.cycle(g));
    CHECK(r.motion->status().last_refused_id == g->id);
    CHECK(r.motion->status().last_refusal == static_cast<std::uint8_t>(ArmMotionReason::hand_retreat));
    CHECK(q_cmd(r) == held);
  }

  ArmGoal lift = measured_lift(5, 30);
  if (turned) KDL::Rotation::RotX(0.2).GetQuaternion(lift.orientation[0][0], lift.orientation[0][1],
                                                     lift.orientation[0][2], lift.orientation[0][3]);
  REQUIRE(r.cycle(&lift));
  for (int i = 0; i < 5000 && r.active(); ++i) r.cycle();  // the hand retreats all along
  const KDL::Frame end = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  MESSAGE("the pad " << 1000.0 * (end.p.z() - low.p.z()) << " mm up; state " << int(r.motion->status().state));
  if (turned) {  // refused as every goal was: the pad stays on the sheet
    CHECK(r.motion->status().last_refused_id == 5);
    CHECK(r.motion->status().last_refusal == static_cast<std::uint8_t>(ArmMotionReason::hand_retreat));
    CHECK(std::abs(1000.0 * (end.p.z() - low.p.z())) < 1e-9);
    return;
  }
  CHECK(r.motion->status().state == ArmMotionStatus::reached);
  CHECK(r.motion->status().goal_id == 5);
  CHECK(1000.0 * (end.p.z() - low.p.z()) > 29.0);
}

// The grasp's back-out (fold_sequence: an abort in the reach, the index under the far edge's
// overhang, where straight up is into the table from below): sideways back the way it came, then
// up, sent as kind retreat, goes while the hand retreats and runs to its end. Failing variant:
// the same path as a plain move is refused (hand_retreat) and nothing moves.
TEST_CASE(
    "while the hand retreats a move of kind retreat goes back the way it came; the same as a move "
    "does not") {
  for (const bool as_retreat : {true, false}) {
    CAPTURE(as_retreat);
    Rig r;
    for (int i = 0; i < 5; ++i) REQUIRE(r.cycle());
    const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
    ArmGoal in = goal_to(ToolFrame::ff_pad, shifted(start, 0, 0, -40), 1, 50, 500);
    add_point(in, shifted(start, 0, -40, -40));
    REQUIRE(r.cycle(&in));
    r.run_to_end();
    REQUIRE(r.motion->status().state == ArmMotionStatus::reached);
    r.hand_control.mode = HandMode::retreat;  // a fingertip over force_limit_n: latched
    r.hand_control.inhibit = HandInhibit::force_limit;
    for (int i = 0; i < 5; ++i) r.cycle();
    const KDL::Frame low = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
    ArmGoal back = goal_to(ToolFrame::ff_pad, shifted(start, 0, 0, -40), 2, 50, 500);
    add_point(back, start);
    if (as_retreat) back.kind = ArmGoal::retreat;
    REQUIRE(r.cycle(&back));
    for (int i = 0; i < 8000 && r.active(); ++i) r.cycle();  // the hand retreats all along
    const KDL::Frame end = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
    if (!as_retreat) {
      CHECK(r.motion->status().last_refused_id == 2);
      CHECK(r.motion->status().last_refusal ==
            static_cast<std::uint8_t>(ArmMotionReason::hand_retreat));
      CHECK(KDL::Equal(end.p, low.p, 1e-9));
      continue;
    }
    CHECK(r.motion->status().state == ArmMotionStatus::reached);
    CHECK(r.motion->status().goal_id == 2);
    CHECK(1000.0 * (end.p - start.p).Norm() < 1.0);  // back where it started
  }
}

// A lift already running when the hand starts to retreat runs to its end; a motion that is
// not a lift (the same 30 mm, 40 mm aside) decelerates and aborts as before.
TEST_CASE("a running lift is not stopped by the hand's retreat; a running move aside is") {
  for (const bool aside : {false, true}) {
    CAPTURE(aside);
    Rig r;
    for (int i = 0; i < 5; ++i) REQUIRE(r.cycle());
    const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
    ArmGoal g = goal_to(ToolFrame::ff_pad, shifted(start, aside ? 40 : 0, 0, 30), 7, 50, 500);
    REQUIRE(r.cycle(&g));
    for (int i = 0; i < 300; ++i) r.cycle();
    REQUIRE(r.motion->status().state == ArmMotionStatus::running);
    r.hand_control.mode = HandMode::retreat;
    r.run_to_end();
    const KDL::Frame end = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
    if (aside) {
      CHECK(r.motion->status().state == ArmMotionStatus::aborted);
      CHECK(r.motion->status().reason == static_cast<std::uint8_t>(ArmMotionReason::hand_retreat));
      CHECK(1000.0 * (end.p.z() - start.p.z()) < 29.0);
    } else {
      CHECK(r.motion->status().state == ArmMotionStatus::reached);
      CHECK(1000.0 * (end.p.z() - start.p.z()) > 29.99);
    }
  }
}

// The path is solved ahead in equal steps of at most check_step_mm: no sliver of a step at a
// segment's end, over which a joint's rate would be the IK's own noise divided by the sliver
// (the fold's abort lift of 30.001 mm, 5 mm steps, refused itself as joint_speed in
// config.sim_sequence). Lengths just over whole steps, up and aside. Failing variant (checked
// by hand: the steps of at most check_step_mm with the remainder last, as before): the
// 30.0000003 and 20.0000002 mm motions are refused as joint_speed, in either frame.
TEST_CASE("a path just over a whole number of check steps is checked and reached, not refused as joint_speed") {
  for (const double len : {30.001, 30.0001, 30.0000003, 20.0000002, 15.0005}) {
    for (const bool ms : {false, true}) {
      CAPTURE(len);
      CAPTURE(ms);
      Rig r;
      for (int i = 0; i < 5; ++i) REQUIRE(r.cycle());
      ArmGoal g = ms ? measured_lift(9, len)
                     : goal_to(ToolFrame::ff_pad, shifted(r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r)), 0, len, 0), 9, 60, 300);
      REQUIRE(r.cycle(&g));
      r.run_to_end();
      CHECK(r.motion->status().state == ArmMotionStatus::reached);
      CHECK(r.motion->status().reasons[static_cast<int>(ArmMotionReason::joint_speed)] == 0);
    }
  }
}

TEST_CASE("while the hand retreats, refusing a press and running a lift allocate nothing") {
  REQUIRE(crease::rt::alloc_hooks_installed());
  Rig r;
  for (int i = 0; i < 5; ++i) REQUIRE(r.cycle());
  const KDL::Frame start = r.tool_pose_at(ToolFrame::ff_pad, q_cmd(r));
  ArmGoal press = goal_to(ToolFrame::ff_pad, shifted(start, 0, 0, -10), 1, 50, 500);
  ArmGoal lift = measured_lift(2, 30);
  r.hand_control.mode = HandMode::retreat;
  r.hand_control.inhibit = HandInhibit::force_limit;
  const auto before = crease::rt::rt_allocation_count();
  {
    crease::rt::ScopedRtMark rt;
    r.cycle(&press);
    r.cycle(&lift);
    r.run_to_end();
  }
  CHECK(crease::rt::rt_allocation_count() == before);
  CHECK(r.motion->status().last_refused_id == 1);
  CHECK(r.motion->status().state == ArmMotionStatus::reached);
}
