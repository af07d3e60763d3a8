// The machine's entry and exit actions: the goals each state of seed 000 Fig. 7 sends to the
// arms' motions (arm_goal), the hands' force controllers (hand_goal) and the sheet model
// (sheet_crease, sheet_memorize). Points from the fold file, in the sheet frame arm_motion
// resolves when each motion starts; the parking poses in the world frame.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "plugins/fold_sequence/machine.h"
#include "plugins/fold_sequence/sheet_geometry.h"

namespace crease::fold {
namespace {

// How far (x, y, mm) the laid layer's nearest node of the tracked sheet may lie from the fixing
// tool for its press to hold it: a cell and a half of the tracking model's 15 mm grid.
constexpr double kPressReachMm = 22.5;

void set_limits(ArmGoal& g, const MotionLimits& l) noexcept {
  g.speed_mm_s = l.speed_mm_s;
  g.accel_mm_s2 = l.accel_mm_s2;
  g.angular_speed_rad_s = l.angular_speed_rad_s;
  g.angular_accel_rad_s2 = l.angular_accel_rad_s2;
  g.stop_accel_mm_s2 = l.stop_accel_mm_s2;
}

// The next arm goal of SIDE in the outbox, cleared, stamped and numbered; null (overflow marked)
// when the side's goals of this step are full.
ArmGoal* next_arm_goal(int side, std::int64_t t_ns, std::uint32_t& next_id, Outbox& out) noexcept {
  if (out.arm_count[side] >= Outbox::kPerPort) {
    out.overflow = true;
    return nullptr;
  }
  ArmGoal& g = out.arm[side][out.arm_count[side]++];
  g = ArmGoal{};
  g.timestamp_ns = t_ns;
  g.id = next_id++;
  return &g;
}

static_assert(kMaxGraspPath + 1 <= ArmGoal::kMaxPoints, "the grasp's path and at_mm are one arm goal");

}  // namespace

void Machine::arm_move(int side, std::uint8_t tool, std::uint8_t frame, const double p[3], const double q[4],
                       const MotionLimits& lim, std::uint8_t stop_fingers, Outbox& out) noexcept {
  const double path[1][3] = {{p[0], p[1], p[2]}};
  const double turn[1][4] = {{q[0], q[1], q[2], q[3]}};
  arm_path(side, tool, frame, 1, path, turn, lim, stop_fingers, out);
}

void Machine::arm_path(int side, std::uint8_t tool, std::uint8_t frame, int n, const double (*path_mm)[3],
                       const double (*orientation)[4], const MotionLimits& lim, std::uint8_t stop_fingers,
                       Outbox& out) noexcept {
  ArmGoal* goal = next_arm_goal(side, m_.last_ns, m_.next_id, out);
  if (goal == nullptr) return;
  ArmGoal& g = *goal;
  n = n < 1 ? 1 : (n > ArmGoal::kMaxPoints ? ArmGoal::kMaxPoints : n);
  const bool held = frame == ArmGoal::sheet && m_.frame_held != 0 && uses_held_frame(m_.leaf);
  g.kind = ArmGoal::move;
  g.tool = tool;
  g.frame = held ? std::uint8_t{ArmGoal::world} : frame;
  g.point_count = static_cast<std::uint8_t>(n);
  g.stop_on = stop_fingers != 0 ? ArmGoal::contact_onset : ArmGoal::stop_none;
  g.stop_fingers = stop_fingers != 0 ? stop_fingers : 0x1f;
  set_limits(g, lim);
  for (int k = 0; k < n; ++k) {
    if (held) {
      sheet_to_world(m_.held_frame, path_mm[k], orientation[k], g.position_mm[k], g.orientation[k]);
      continue;
    }
    for (int c = 0; c < 3; ++c) g.position_mm[k][c] = path_mm[k][c];
    for (int c = 0; c < 4; ++c) g.orientation[k][c] = orientation[k][c];
  }
  m_.arm_id[side] = g.id;
  m_.arm_sent_ns[side] = m_.last_ns;
  m_.arm_has_target[side] = 1;
  m_.arm_frame[side] = g.frame;
  m_.arm_tool[side] = tool;
  for (int c = 0; c < 3; ++c) m_.arm_target[side][c] = g.position_mm[n - 1][c];
  for (int c = 0; c < 4; ++c) m_.arm_orientation[side][c] = g.orientation[n - 1][c];
}

bool Machine::uses_held_frame(S s) noexcept {
  return is_within(s, S::fixate_layer) || is_within(s, S::refixate) || is_within(s, S::swipe) ||
         is_within(s, S::harden);
}

void Machine::arm_stop(int side, Outbox& out) noexcept {
  ArmGoal* g = next_arm_goal(side, m_.last_ns, m_.next_id, out);
  if (g == nullptr) return;
  g->kind = ArmGoal::stop;
  m_.arm_id[side] = 0;  // a stop is not waited for by id: the arm is still when it no longer moves
}

void Machine::arm_lift(int side, double lift_mm, Outbox& out) noexcept {
  if (!m_.arm_has_target[side]) return;  // never moved: where it parked
  // Straight up from where the tool is measured to be (arm_motion's `measured` frame), not from
  // the last target: a motion stopped on its way (a contact, an abort) left the arm short of it,
  // and a line from there to above the target could sweep through the sheet. The orientation
  // is kept.
  const double p[3] = {0.0, 0.0, lift_mm};
  const double q[4] = {0.0, 0.0, 0.0, 1.0};
  arm_move(side, m_.arm_tool[side], ArmGoal::measured, p, q, spec_.retreat, 0, out);
}

bool Machine::back_out_of_grasp(Outbox& out) noexcept {
  if (m_.aborted_from != S::grasp_reach && m_.aborted_from != S::grasp_pinch) return false;
  if (!m_.arm_has_target[kPinching]) return false;
  // The pinching tool went in under the sheet's edge round its overhang (grasp_path_mm, e.g.
  // under the table top beyond its edge): straight up from there is into the table from below.
  // Back out the way it came, then to above_mm; slowly (contact limits), as it went in.
  // The reach's points are path 0..n-1 then at_mm; segment k runs towards point k, so points
  // 0..k-1 were passed (the pinch: all of them; unknown: none, it was still above).
  const FoldSpec& f = spec_;
  const int n = f.grasp_path_count;
  int passed = n;
  if (m_.aborted_from == S::grasp_reach)
    passed = m_.aborted_segment == Memory::kNoSegment ? 0 : std::min<int>(m_.aborted_segment, n);
  double path[kMaxGraspPath + 1][3], turn[kMaxGraspPath + 1][4];
  for (int k = 0; k <= passed; ++k) {
    for (int c = 0; c < 3; ++c)
      path[k][c] = k < passed ? f.grasp_path_mm[passed - 1 - k][c] : f.grasp_above_mm[c];
    for (int c = 0; c < 4; ++c) turn[k][c] = f.grasp_orientation[c];
  }
  const int before = out.arm_count[kPinching];
  arm_path(kPinching, f.grasp_tool, ArmGoal::sheet, passed + 1, path, turn, f.contact, 0, out);
  if (out.arm_count[kPinching] > before)
    out.arm[kPinching][before].kind = ArmGoal::retreat;  // taken while the hand retreats
  return true;
}

int Machine::bend_passed() const noexcept {
  if (m_.aborted_from != S::follow_via && m_.aborted_from != S::layer_lay) return 0;
  if (!m_.arm_has_target[kPinching]) return 0;
  return m_.aborted_from == S::layer_lay ? spec_.via_count : std::min<int>(m_.via, spec_.via_count);
}

bool Machine::above_via_in_sheet(int k, const Sensing& in, double p[3],
                                 double q[4]) const noexcept {
  const FoldSpec& f = spec_;
  if (!f.grasp_above_via_world[k]) {
    for (int c = 0; c < 3; ++c) p[c] = f.grasp_above_via_mm[k][c];
    for (int c = 0; c < 4; ++c) q[c] = f.grasp_above_via_orientation[k][c];
    return true;
  }
  SheetFrame frame;
  if (in.sheet == nullptr || !sheet_frame(*in.sheet, frame)) return false;
  world_to_sheet(frame, f.grasp_above_via_mm[k], f.grasp_above_via_orientation[k], p, q);
  return true;
}

bool Machine::back_out_of_bend(const Sensing& in, Outbox& out) noexcept {
  // A pinch turned by the bend, lifted 30 mm and parked on a line (or in joint space, a line
  // being out of reach there) swept the hand through the table (trials: 3443 N; 17.7 N, the
  // park timed out). The way it came is within reach: via points k-1 .. 0 (the motion to via
  // k was running; from the lay: all), above_mm, above_via in reverse.
  const FoldSpec& f = spec_;
  const int passed = bend_passed();
  const int tail = 1 + f.grasp_above_via_count;  // above_mm and the above_via points
  const int room = ArmGoal::kMaxPoints - tail;
  if (passed == 0 || room < 1) return false;  // still by the grasp: lifted as before
  const int step = passed <= room ? 1 : (passed + room - 1) / room;
  double path[ArmGoal::kMaxPoints][3], turn[ArmGoal::kMaxPoints][4];
  int n = 0;
  const auto add = [&](const double* p, const double* q) {
    for (int c = 0; c < 3; ++c) path[n][c] = p[c];
    for (int c = 0; c < 4; ++c) turn[n][c] = q[c];
    ++n;
  };
  double vq[4];
  for (int i = passed - 1; i >= 0 && n < room; i -= step) {
    via_orientation(i, vq);
    add(f.via_mm[i], vq);
  }
  if ((passed - 1) % step != 0) {  // via 0 skipped by the step: it ends the bend's way back
    if (n == room) --n;
    via_orientation(0, vq);
    add(f.via_mm[0], vq);
  }
  add(f.grasp_above_mm, f.grasp_orientation);
  for (int i = f.grasp_above_via_count - 1; i >= 0; --i) {
    double p[3], q[4];
    if (above_via_in_sheet(i, in, p, q)) add(p, q);
  }
  const int before = out.arm_count[kPinching];
  arm_path(kPinching, f.grasp_tool, ArmGoal::sheet, n, path, turn, f.fold, 0, out);
  if (out.arm_count[kPinching] > before)
    out.arm[kPinching][before].kind = ArmGoal::retreat;  // taken while the hand retreats
  return true;
}

void Machine::arm_park(int side, Outbox& out, bool joints) noexcept {
  const int s = side_of_role(spec_, side);  // park poses are per side
  const int before = out.arm_count[side];
  arm_move(side, m_.arm_has_target[side] ? m_.arm_tool[side] : 0, ArmGoal::world, spec_.park_mm[s],
           spec_.park_orientation[s], spec_.retreat, 0, out);
  if (joints && out.arm_count[side] > before) out.arm[side][before].interpolation = ArmGoal::joints;
}

bool Machine::joints_park_due(int s, const Sensing& in) const noexcept {
  const ArmMotionStatus* a = in.arm[s];
  if (m_.leaf != S::abort_park || m_.park_joints[s] || retreat_end(a, m_.arm_id[s]) != RetreatEnd::gave_up) return false;
  const auto why = static_cast<ArmMotionReason>(end_reason(*a, m_.arm_id[s]));
  return why == ArmMotionReason::unreachable || why == ArmMotionReason::joint_speed;
}

void Machine::via_orientation(int k, double q[4]) const noexcept {
  const FoldSpec& f = spec_;
  for (int c = 0; c < 4; ++c) q[c] = f.via_orientation[k][c];
  if (!f.bend_yaw_limited || m_.frame_held == 0) return;
  constexpr double kDeg = std::numbers::pi / 180.0;
  const double yaw = std::remainder(frame_yaw(m_.held_frame) - f.bend_yaw_reference_deg * kDeg,
                                    2 * std::numbers::pi);
  const double kept =
      std::clamp(yaw, f.bend_yaw_range_deg[0] * kDeg, f.bend_yaw_range_deg[1] * kDeg);
  if (kept != yaw) turn_about_vertical(m_.held_frame, kept - yaw, f.via_orientation[k], q);
}

void Machine::pinch_as_laid(const double p[3], Outbox& out) noexcept {
  double q[4];
  via_orientation(spec_.via_count - 1, q);
  arm_move(kPinching, spec_.grasp_tool, ArmGoal::sheet, p, q, spec_.contact, 0, out);
}

void Machine::push_hand(int side, HandGoal g, const Sensing& in, Outbox& out) noexcept {
  if (out.hand_count[side] >= Outbox::kPerPort) {
    out.overflow = true;
    return;
  }
  g.timestamp_ns = m_.last_ns;
  g.id = m_.next_id++;
  out.hand[side][out.hand_count[side]++] = g;
  m_.hand_id[side] = g.id;
  m_.hand_mode[side] = g.mode;
  m_.hand_refused0[side] = in.hand[side] != nullptr ? in.hand[side]->goals_refused : 0;
}

void Machine::hand_posture(int side, const float* target_rad, const Sensing& in, Outbox& out,
                           const float* stiffness, double ramp_s) noexcept {
  HandGoal g{};
  g.mode = HandMode::posture;
  g.ramp_s = static_cast<float>(ramp_s >= 0 ? ramp_s : spec_.posture_ramp_s);
  for (int j = 0; j < kHandJoints; ++j) g.target_rad[j] = target_rad[j];
  if (stiffness != nullptr) {
    g.set_stiffness = 1;
    for (int j = 0; j < kHandJoints; ++j) g.stiffness_nm_per_rad[j] = stiffness[j];
  }
  push_hand(side, g, in, out);
}

void Machine::hand_force(int side, std::uint8_t fingers, double force_n, const Sensing& in, Outbox& out) noexcept {
  HandGoal g{};
  g.mode = HandMode::force;
  g.fingers = static_cast<std::uint8_t>(fingers & 0x0f);  // the thumb never presses
  g.force_n = static_cast<float>(force_n);
  g.ramp_s = static_cast<float>(spec_.force_ramp_s);
  m_.force_fingers[side] = g.fingers;
  m_.force_n[side] = g.force_n;
  push_hand(side, g, in, out);
}

void Machine::hand_hold(int side, const Sensing& in, Outbox& out) noexcept {
  HandGoal g{};
  g.mode = HandMode::hold;
  push_hand(side, g, in, out);
}

void Machine::approach(int side, const ContactStep& c, Outbox& out) noexcept {
  const double p[3] = {c.at_mm[0], c.at_mm[1], -c.approach_height_mm};
  arm_move(side, c.tool, ArmGoal::sheet, p, c.orientation, spec_.approach, 0, out);
}

void Machine::descend(int side, const ContactStep& c, Outbox& out) noexcept {
  const double p[3] = {c.at_mm[0], c.at_mm[1], c.contact_depth_mm};  // below the surface: stops on contact
  arm_move(side, c.tool, ArmGoal::sheet, p, c.orientation, spec_.contact, c.fingers, out);
}

void Machine::stop_for_pause(Outbox& out) noexcept {
  for (int s = 0; s < 2; ++s) {
    arm_stop(s, out);
    m_.hand_id[s] = 0;
  }
  // Hands that press keep their targets (hold); the others keep their posture as it is.
  const Sensing none{};
  for (int s = 0; s < 2; ++s) {
    m_.held_by_pause[s] = m_.hand_mode[s] == HandMode::force ? 1 : 0;
    if (m_.held_by_pause[s]) hand_hold(s, none, out);
  }
  for (int s = 0; s < 2; ++s) m_.hand_id[s] = 0;
}

bool Machine::park_out_of_reach(int s, const Sensing& in, Outbox& out) noexcept {
  const auto lift = [&](double mm) {
    m_.park_joints[s] = Memory::kParkLifting;
    m_.park_lift_mm[s] = mm;
    out.park_lift[s] = true;
    arm_lift(s, mm, out);
  };
  const auto park_in_joints = [&] {
    m_.park_joints[s] = Memory::kParkJoints;
    out.joints_park[s] = true;
    arm_park(s, out, true);
  };
  if (joints_park_due(s, in)) {  // the park on a line out of reach: up first, then in joint space
    if (spec_.park_lift_mm > 0)
      lift(spec_.park_lift_mm);
    else
      park_in_joints();
    return true;
  }
  if (m_.park_joints[s] != Memory::kParkLifting) return false;
  const ArmMotionStatus* a = in.arm[s];
  const RetreatEnd e = retreat_end(a, m_.arm_id[s]);
  if (e == RetreatEnd::pending) return true;  // rising
  if (e == RetreatEnd::gave_up && m_.park_lift_mm[s] * 0.5 >= Memory::kMinParkLiftMm) {
    const auto why = static_cast<ArmMotionReason>(end_reason(*a, m_.arm_id[s]));
    if (why == ArmMotionReason::unreachable || why == ArmMotionReason::joint_speed) {
      lift(m_.park_lift_mm[s] * 0.5);  // a shorter lift
      return true;
    }
  }
  park_in_joints();  // the lift ended (reached or short)
  return true;
}

void Machine::retry_retreat(const Sensing& in, Outbox& out) noexcept {
  if (m_.leaf != S::abort_lift && m_.leaf != S::abort_park) return;
  for (int s = 0; s < 2; ++s) {
    const ArmMotionStatus* a = in.arm[s];
    if (park_out_of_reach(s, in, out)) continue;
    if (retreat_end(a, m_.arm_id[s]) != RetreatEnd::retry ||
        static_cast<double>(m_.last_ns - m_.arm_sent_ns[s]) * 1e-9 < kRetryS)
      continue;
    out.retried[s] = end_reason(*a, m_.arm_id[s]);
    if (m_.leaf == S::abort_lift) {
      if (s == kPinching && back_out_of_grasp(out)) continue;  // the way it came, again
      arm_lift(s, spec_.release_lift_mm, out);  // from where it is now: up again
      continue;
    }
    const HandControlStatus* h = in.hand[s];
    if (h != nullptr && (h->mode == HandMode::retreat || h->inhibit != HandInhibit::none))
      hand_posture(s, spec_.open_rad, in, out);  // taken, it clears the latch that refuses the park
    arm_park(s, out, m_.park_joints[s] != 0);
  }
}

void Machine::report_retreat(const Sensing& in, Outbox& out) noexcept {
  if (m_.leaf != S::abort_lift && m_.leaf != S::abort_park) return;
  for (int s = 0; s < 2; ++s) {
    const ArmMotionStatus* a = in.arm[s];
    if (m_.arm_id[s] == 0 || m_.gave_up_id[s] == m_.arm_id[s] || retreat_end(a, m_.arm_id[s]) != RetreatEnd::gave_up ||
        joints_park_due(s, in))
      continue;
    m_.gave_up_id[s] = m_.arm_id[s];
    out.gave_up[s] = end_reason(*a, m_.arm_id[s]);
  }
}

void Machine::exit(S s, const Sensing& in, Outbox& out) noexcept {
  (void)in;
  (void)out;
  (void)s;  // no state leaves anything behind: its goals are replaced by the next state's
}

void Machine::enter(S s, const Sensing& in, Outbox& out) noexcept {
  m_.elapsed_ns[static_cast<int>(s)] = 0;
  if (is_leaf(s)) {
    m_.arm_id[0] = m_.arm_id[1] = 0;  // the goals waited for are the ones this state sends
    m_.hand_id[0] = m_.hand_id[1] = 0;
  }
  const FoldSpec& f = spec_;
  switch (s) {
    case S::fold:
      // An inhibit the force controller latched before the fold (it clears on its next goal)
      // is not this fold's fault: only new ones count.
      for (int s2 = 0; s2 < 2; ++s2) m_.inhibits0[s2] = in.hand[s2] != nullptr ? in.hand[s2]->inhibits : 0;
      m_.via = 0;
      m_.slides = 0;
      m_.vision_bad_since_ns = 0;
      m_.frame_held = 0;
      m_.abort_reason = Reason::none;
      break;
    case S::shift_approach:
      hand_posture(kFixing, f.open_rad, in, out);
      hand_posture(kPinching, f.open_rad, in, out);
      approach(f.shift_role, f.shift, out);
      break;
    case S::shift_contact:
      descend(f.shift_role, f.shift, out);
      break;
    case S::shift_press:
      hand_force(f.shift_role, f.shift.fingers, f.shift.force_n, in, out);
      break;
    case S::shift_slide: {
      double d[2] = {0, 0}, w[2] = {0, 0};
      const double len = slide_length(in, d, w);
      if (!std::isfinite(len))
        d[0] = d[1] = w[0] = w[1] = 0;  // the guard saw a sheet; a stale one here moves nothing
      if (m_.slides++ == 0) {           // from the press point, in the sheet's frame
        const double p[3] = {f.shift.at_mm[0] + d[0], f.shift.at_mm[1] + d[1], -f.slide_height_mm};
        arm_move(f.shift_role, f.shift.tool, ArmGoal::sheet, p, f.shift.orientation, f.slide, 0,
                 out);
      } else {  // the rest, from where the finger is (it slipped over the sheet): the corner's way
                // in the world
        const double p[3] = {w[0], w[1], 0.0}, keep[4] = {0, 0, 0, 1};
        arm_move(f.shift_role, f.shift.tool, ArmGoal::measured, p, keep, f.slide, 0, out);
      }
      break;
    }
    // The pinching hand shifted: it opens and lifts off, the fixing hand comes down on
    // grasp.fixate.
    case S::grasp_open:
      hand_posture(kPinching, f.open_rad, in, out);
      break;
    case S::grasp_lift:
      arm_lift(kPinching, f.shift_lift_mm, out);
      break;
    case S::grasp_park:
      arm_park(kPinching, out, true);
      break;
    case S::grasp_fix_approach:
      approach(kFixing, f.fixate, out);
      break;
    case S::grasp_fix_contact:
      descend(kFixing, f.fixate, out);
      break;
    case S::grasp_fixate:
      hand_force(kFixing, f.fixate.fingers, f.fixate_force_n, in, out);
      break;
    case S::grasp_shape: hand_posture(kPinching, f.prepinch_rad, in, out); break;
    case S::grasp_above: {
      double path[kMaxGraspPath + 1][3], turn[kMaxGraspPath + 1][4];
      int n = 0;  // a world point without a tracked sheet to put it in is left out
      for (int k = 0; k < f.grasp_above_via_count; ++k)
        if (above_via_in_sheet(k, in, path[n], turn[n])) ++n;
      for (int c = 0; c < 3; ++c) path[n][c] = f.grasp_above_mm[c];
      for (int c = 0; c < 4; ++c) turn[n][c] = f.grasp_orientation[c];
      arm_path(kPinching, f.grasp_tool, ArmGoal::sheet, n + 1, path, turn, f.approach, 0, out);
      break;
    }
    case S::grasp_reach: {
      double path[kMaxGraspPath + 1][3], turn[kMaxGraspPath + 1][4];
      const int n = f.grasp_path_count;
      for (int k = 0; k <= n; ++k) {
        for (int c = 0; c < 3; ++c) path[k][c] = k < n ? f.grasp_path_mm[k][c] : f.grasp_at_mm[c];
        for (int c = 0; c < 4; ++c) turn[k][c] = f.grasp_orientation[c];
      }
      arm_path(kPinching, f.grasp_tool, ArmGoal::sheet, n + 1, path, turn, f.contact, 0, out);
      break;
    }
    case S::grasp_pinch: hand_posture(kPinching, f.pinch_rad, in, out); break;
    case S::bend:
      // The crease the fold intends, in the tracked sheet's coordinates, so the model can bend.
      out.crease = SheetCreaseEvent{};
      out.crease.timestamp_ns = m_.last_ns;
      out.crease.op = SheetCreaseEvent::Op::add;
      for (int c = 0; c < 2; ++c) {
        out.crease.a_mm[c] = static_cast<float>(f.fold_line_mm[0][c]);
        out.crease.b_mm[c] = static_cast<float>(f.fold_line_mm[1][c]);
      }
      out.has_crease = true;
      m_.crease_count0 = in.sheet != nullptr ? in.sheet->crease_count : 0;
      m_.frame_held = in.sheet != nullptr && sheet_frame(*in.sheet, m_.held_frame) ? 1 : 0;
      break;
    case S::follow_via: {
      if (m_.self_entry) ++m_.via;  // the next via point; re-entered on resume: the same one
      double q[4];
      via_orientation(m_.via, q);
      arm_move(kPinching, f.grasp_tool, ArmGoal::sheet, f.via_mm[m_.via], q, f.fold, 0, out);
      break;
    }
    case S::bend_crease: m_.via = 0; break;
    case S::layer_lay: pinch_as_laid(f.lay_mm, out); break;
    case S::refix_slide_out: {
      // Out from under the bent layer along the table, pressing lightly: the near half stays.
      hand_force(kFixing, f.fixate.fingers, f.refixate_out_force_n, in, out);
      const double p[3] = {f.refixate_out_mm[0], f.refixate_out_mm[1], -f.slide_height_mm};
      arm_move(kFixing, f.fixate.tool, ArmGoal::sheet, p, f.fixate.orientation, f.slide, 0, out);
      break;
    }
    case S::refix_open: hand_posture(kFixing, f.open_rad, in, out); break;
    case S::refix_lift: arm_lift(kFixing, f.release_lift_mm, out); break;
    case S::refix_approach: approach(kFixing, f.refixate, out); break;
    case S::refix_contact: descend(kFixing, f.refixate, out); break;
    case S::refix_press: {
      hand_force(kFixing, f.refixate.fingers, f.refixate.force_n, in, out);
      // The laid layer's point under the fixing tool, as the model has it now (the pinch still
      // holds the layer): what this press holds from now on (press_target).
      const ArmMotionStatus* a = in.arm[kFixing];
      m_.press_held = 0;
      if (in.sheet != nullptr && a != nullptr && a->tool_measured != 0 && a->all_finite()) {
        const double p[3] = {a->tool_mm[0], a->tool_mm[1], a->tool_mm[2]};
        m_.press_held = part_point_under(*in.sheet, f.fold_line_mm[0], f.fold_line_mm[1],
                                         f.grasp_at_mm, p, kPressReachMm, m_.press_uv)
                            ? 1
                            : 0;
      }
      break;
    }
    case S::swipe_release:
      hand_posture(kPinching, f.prepinch_rad, in, out,
                   f.has_release_stiffness ? f.release_stiffness : nullptr, f.release_ramp_s);
      break;
    case S::swipe_withdraw: pinch_as_laid(f.swipe_withdraw_mm, out); break;
    case S::swipe_open:
    case S::harden_open: hand_posture(kPinching, f.open_rad, in, out); break;
    case S::swipe_lift:
    case S::harden_lift: arm_lift(kPinching, f.release_lift_mm, out); break;
    case S::swipe_approach: approach(kPinching, f.swipe, out); break;
    case S::swipe_contact: descend(kPinching, f.swipe, out); break;
    case S::swipe_press: hand_force(kPinching, f.swipe.fingers, f.swipe.force_n, in, out); break;
    case S::swipe_slide: {
      const double p[3] = {f.swipe_to_mm[0], f.swipe_to_mm[1], -f.slide_height_mm};
      arm_move(kPinching, f.swipe.tool, ArmGoal::sheet, p, f.swipe.orientation, f.slide, 0, out);
      break;
    }
    case S::harden_approach: {
      // The stroke along the crease as the model has it (nearest to the intended line; the
      // intended line when the model has none), inset from its ends, offset across it.
      double a[2] = {f.fold_line_mm[0][0], f.fold_line_mm[0][1]};
      double b[2] = {f.fold_line_mm[1][0], f.fold_line_mm[1][1]};
      if (in.sheet != nullptr) (void)nearest_crease(*in.sheet, a, b);
      const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
      const double dir[2] = {len > 0 ? (b[0] - a[0]) / len : 1.0, len > 0 ? (b[1] - a[1]) / len : 0.0};
      const double nrm[2] = {-dir[1], dir[0]};
      const double inset = len > 2 * f.harden_inset_mm ? f.harden_inset_mm : 0.0;
      for (int c = 0; c < 2; ++c) {
        m_.harden_a[c] = a[c] + dir[c] * inset + nrm[c] * f.harden_offset_mm;
        m_.harden_b[c] = b[c] - dir[c] * inset + nrm[c] * f.harden_offset_mm;
      }
      ContactStep h = f.harden;
      h.at_mm[0] = m_.harden_a[0];
      h.at_mm[1] = m_.harden_a[1];
      approach(kPinching, h, out);
      break;
    }
    case S::harden_contact: {
      ContactStep h = f.harden;
      h.at_mm[0] = m_.harden_a[0];
      h.at_mm[1] = m_.harden_a[1];
      descend(kPinching, h, out);
      break;
    }
    case S::harden_press: hand_force(kPinching, f.harden.fingers, f.harden.force_n, in, out); break;
    case S::harden_slide: {
      const double p[3] = {m_.harden_b[0], m_.harden_b[1], -f.slide_height_mm};
      arm_move(kPinching, f.harden.tool, ArmGoal::sheet, p, f.harden.orientation, f.slide, 0, out);
      break;
    }
    case S::finish_memorize:
      out.memorize = SheetMemorizeEvent{};
      out.memorize.timestamp_ns = m_.last_ns;
      out.memorize.whole_sheet = true;
      out.has_memorize = true;
      m_.sheet_step0 = in.sheet != nullptr ? in.sheet->step : 0;
      break;
    case S::finish_open:
    case S::abort_reopen:
      hand_posture(kFixing, f.open_rad, in, out);
      hand_posture(kPinching, f.open_rad, in, out);
      break;
    case S::abort_open:
      hand_posture(kFixing, f.open_rad, in, out);
      // A pinch the bend carried lets go with its thumb only (prepinch): the lift backs it out the
      // way it came (back_out_of_bend), which the index's pad frame reaches as long as the index
      // keeps its curl (opened, the pad moved and arm_motion refused the way as unreachable, and
      // the park in joint space swept the hand through the table). It opens in `reopen`, above.
      hand_posture(kPinching, bend_passed() > 0 ? f.prepinch_rad : f.open_rad, in, out);
      break;
    case S::finish_lift:
      arm_lift(kFixing, f.release_lift_mm, out);
      arm_lift(kPinching, f.release_lift_mm, out);
      break;
    case S::abort_lift:
      arm_lift(kFixing, f.release_lift_mm, out);
      if (!back_out_of_grasp(out) && !back_out_of_bend(in, out))
        arm_lift(kPinching, f.release_lift_mm, out);
      break;
    case S::finish_park:
    case S::abort_park:
      m_.park_joints[0] = m_.park_joints[1] = 0;
      m_.park_lift_mm[0] = m_.park_lift_mm[1] = 0;
      arm_park(kFixing, out);
      arm_park(kPinching, out);
      break;
    case S::abort: ++m_.aborts; break;
    case S::abort_stop:
      // Stop force first (hold the targets), and the arms where they are.
      hand_hold(kFixing, in, out);
      hand_hold(kPinching, in, out);
      arm_stop(kFixing, out);
      arm_stop(kPinching, out);
      break;
    default: break;
  }
}

}  // namespace crease::fold
