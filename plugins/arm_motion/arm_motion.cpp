#include "plugins/arm_motion/arm_motion.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

namespace crease::arm_motion {

namespace {
using robot::kArmJoints;
constexpr std::uint8_t kOperationEnabled = 4;  // drivers::cia402::State
constexpr std::uint8_t kDriveFault = 7;

bool active(std::uint8_t phase) noexcept {
  return phase == ArmMotionStatus::checking || phase == ArmMotionStatus::running ||
         phase == ArmMotionStatus::stopping;
}
}  // namespace

static_assert(std::is_trivially_copyable_v<MotionState>, "a hot-swap copies the motion's bytes");

ArmMotion::ArmMotion(const robot::RobotModel& model, robot::Side side, const MotionParams& params)
    : p_(params), ik_(model, side, params.ik) {
  s_.size = sizeof(MotionState);
}

ArmMotion::Readiness ArmMotion::arm_readiness(const CycleInputs& in) const noexcept {
  if (in.arm == nullptr) return Readiness::stale;
  if (static_cast<double>(in.now_ns - in.arm->timestamp_ns) * 1e-9 > p_.arm_state_max_age_s) return Readiness::stale;
  if (in.arm->health == DeviceHealth::fault || in.arm->drive_state == kDriveFault ||
      in.arm->drive_state != kOperationEnabled || !in.arm->all_finite()) {
    return Readiness::fault;
  }
  return Readiness::ready;
}

bool ArmMotion::contact_fresh(const CycleInputs& in) const noexcept {
  return in.contact != nullptr && in.contact->armed && in.contact->healthy &&
         static_cast<double>(in.now_ns - in.contact->timestamp_ns) * 1e-9 <= p_.contact_state_max_age_s;
}

bool ArmMotion::hand_retreating(const CycleInputs& in) const noexcept {
  const HandControlStatus* h = in.hand_control;
  return h != nullptr && (h->mode == HandMode::retreat || h->inhibit != HandInhibit::none ||
                          static_cast<double>(in.now_ns - h->timestamp_ns) * 1e-9 > p_.hand_state_max_age_s);
}

void ArmMotion::refuse(std::uint32_t id, ArmMotionReason r) noexcept {
  ArmMotionStatus& st = s_.status;
  ++st.goals_refused;
  ++st.reasons[static_cast<int>(r)];
  st.last_refused_id = id;
  st.last_refusal = static_cast<std::uint8_t>(r);
  if (!active(s_.phase)) {  // a motion in progress goes on; its state stays on the status
    const bool unreachable = r == ArmMotionReason::unreachable || r == ArmMotionReason::joint_speed;
    s_.phase = unreachable ? ArmMotionStatus::unreachable : ArmMotionStatus::refused;
    st.goal_id = id;
    st.reason = static_cast<std::uint8_t>(r);
  }
}

void ArmMotion::finish(ArmMotionStatus::State st, ArmMotionReason r) noexcept {
  s_.phase = st;
  s_.status.reason = static_cast<std::uint8_t>(r);
  for (double& v : s_.v_cmd) v = 0;
  if (st == ArmMotionStatus::aborted) {
    ++s_.status.motions_aborted;
    ++s_.status.reasons[static_cast<int>(r)];
  }
}

void ArmMotion::begin_stop(ArmMotionStatus::State end, ArmMotionReason r) noexcept {
  s_.phase = ArmMotionStatus::stopping;
  s_.profile.stopping = 1;
  if (s_.joint_move) stop_joint_profile(s_.joint, s_.v_cmd);
  s_.end_state = end;
  s_.end_reason = static_cast<std::uint8_t>(r);
}

void ArmMotion::on_goal(const ArmGoal& g, const CycleInputs& in, const KDL::Frame* world_sheet) noexcept {
  if (g.kind == ArmGoal::stop) {
    if (s_.phase == ArmMotionStatus::checking) {
      finish(ArmMotionStatus::aborted, ArmMotionReason::stopped);  // nothing moved yet
    } else if (s_.phase == ArmMotionStatus::running) {
      begin_stop(ArmMotionStatus::aborted, ArmMotionReason::stopped);
    }
    return;
  }
  ArmMotionReason r = check_goal(g, p_.limits);
  const auto tool = static_cast<robot::ToolFrame>(g.tool);
  if (r == ArmMotionReason::none && active(s_.phase)) r = ArmMotionReason::busy;
  if (r == ArmMotionReason::none && (!s_.have_cmd || arm_readiness(in) != Readiness::ready)) {
    r = ArmMotionReason::arm_not_ready;
  }
  if (r == ArmMotionReason::none && tool != robot::ToolFrame::flange &&
      (in.hand == nullptr || in.hand->health == DeviceHealth::fault || !in.hand->all_finite() ||
       static_cast<double>(in.now_ns - in.hand->timestamp_ns) * 1e-9 > p_.hand_state_max_age_s)) {
    r = ArmMotionReason::no_hand_state;
  }
  if (r == ArmMotionReason::none && g.stop_on != ArmGoal::stop_none && !contact_fresh(in)) {
    r = ArmMotionReason::no_contact_state;
  }
  if (r == ArmMotionReason::none && g.frame == ArmGoal::sheet && world_sheet == nullptr) r = ArmMotionReason::no_sheet;
  // The points in the world frame, metres (relative to the measured pose: below, once the tool is set).
  CartesianPath path;
  if (r == ArmMotionReason::none && g.frame != ArmGoal::measured) {
    const KDL::Frame frame = g.frame == ArmGoal::sheet ? *world_sheet : KDL::Frame::Identity();
    for (int k = 0; k < g.point_count && r == ArmMotionReason::none; ++k) {
      const double* q = g.orientation[k];
      const KDL::Frame local(KDL::Rotation::Quaternion(q[0], q[1], q[2], q[3]),
                             KDL::Vector(g.position_mm[k][0], g.position_mm[k][1], g.position_mm[k][2]) / 1000.0);
      const KDL::Frame world = frame * local;
      const double p_mm[3] = {1000.0 * world.p.x(), 1000.0 * world.p.y(), 1000.0 * world.p.z()};
      if (!p_.workspace.contains(p_mm)) r = ArmMotionReason::outside_workspace;
      path.pose[k + 1] = to_pose(world);
    }
  }
  if (r != ArmMotionReason::none) {
    refuse(g.id, r);
    return;
  }
  // Accepted: the tool frame's offset from the hand as it is now, the path from where the
  // tool is commanded to be.
  std::array<double, robot::kHandJoints> hand{};
  if (in.hand != nullptr)
    for (int j = 0; j < robot::kHandJoints; ++j) hand[j] = in.hand->position_rad[j];
  const std::span<const double, kArmJoints> q_cmd(s_.q_cmd, kArmJoints);
  if (!ik_.set_tool(tool, q_cmd, hand)) {
    refuse(g.id, ArmMotionReason::unreachable);
    return;
  }
  const KDL::Frame off = ik_.tool_offset();
  const PathPose o = to_pose(off);
  ik_.set_tool_offset(tool, to_frame(o));  // as load_state will: a swapped motion runs the same numbers
  double q_goal[kArmJoints];
  if (g.interpolation == ArmGoal::joints) {
    const PathPose& t = path.pose[1];
    const KDL::Frame target = to_frame(t);
    const std::span<const double, kArmJoints> seed(s_.have_home ? s_.home_q : s_.q_cmd, kArmJoints);
    if (!ik_.solve(target, seed, std::span<double, kArmJoints>(q_goal, kArmJoints)).converged) {
      refuse(g.id, ArmMotionReason::unreachable);
      return;
    }
  }
  if (g.frame == ArmGoal::measured) {
    // From where the arm is (its readiness above: a fresh arm_state), not where it was commanded.
    double q_meas[kArmJoints];
    for (int j = 0; j < kArmJoints; ++j) q_meas[j] = in.arm->position_rad[j];
    const KDL::Frame here = ik_.tool_pose(std::span<const double, kArmJoints>(q_meas, kArmJoints));
    for (int k = 0; k < g.point_count; ++k) {
      const double* q = g.orientation[k];
      const KDL::Frame world(KDL::Rotation::Quaternion(q[0], q[1], q[2], q[3]) * here.M,
                             here.p + KDL::Vector(g.position_mm[k][0], g.position_mm[k][1], g.position_mm[k][2]) / 1000.0);
      const double p_mm[3] = {1000.0 * world.p.x(), 1000.0 * world.p.y(), 1000.0 * world.p.z()};
      if (!p_.workspace.contains(p_mm)) {
        refuse(g.id, ArmMotionReason::outside_workspace);
        return;
      }
      path.pose[k + 1] = to_pose(world);
    }
  }
  path.pose[0] = to_pose(ik_.tool_pose(q_cmd));
  path.count = g.point_count + 1;
  // While the hand retreats only a lift, or a retreat the sender vouches for, goes (away from
  // what it pressed); any other is refused.
  const bool lift =
      g.kind == ArmGoal::retreat || (g.interpolation == ArmGoal::cartesian && path_is_lift(path));
  if (!lift && hand_retreating(in)) {
    refuse(g.id, ArmMotionReason::hand_retreat);
    return;
  }
  std::memcpy(s_.offset_p, o.p_m, sizeof(s_.offset_p));
  std::memcpy(s_.offset_quat, o.quat, sizeof(s_.offset_quat));
  set_path_limits(path, PathLimits{g.speed_mm_s * 1e-3, g.accel_mm_s2 * 1e-3, g.angular_speed_rad_s,
                                   g.angular_accel_rad_s2, g.stop_accel_mm_s2 * 1e-3, p_.jerk_mm_s3 * 1e-3,
                                   p_.angular_jerk_rad_s3, p_.stop_jerk_mm_s3 * 1e-3});
  s_.path = path;
  s_.profile = PathProfile{};
  s_.phase = ArmMotionStatus::checking;
  s_.joint_move = g.interpolation == ArmGoal::joints ? 1 : 0;
  s_.tool = g.tool;
  s_.stop_on = g.stop_on;
  s_.stop_fingers = g.stop_fingers;
  s_.lift = lift ? 1 : 0;
  s_.onsets_at_start = in.contact != nullptr ? in.contact->onsets : 0;
  s_.stop_fingers_held = in.contact != nullptr && in.contact->in_contact != 0
                             ? static_cast<std::uint8_t>(in.contact->fingers & g.stop_fingers)
                             : 0;
  s_.check_segment = 0;
  s_.check_sigma = 0;
  std::memcpy(s_.q_check, s_.q_cmd, sizeof(s_.q_check));
  s_.status.goal_id = g.id;
  s_.status.reason = 0;
  s_.status.tool = g.tool;
  if (s_.joint_move) {  // within the limits all the way: runs from this cycle
    double vmax[kArmJoints];
    for (int j = 0; j < kArmJoints; ++j) vmax[j] = p_.joint_speed_fraction * ik_.velocity_limit()[j];
    s_.joint = joint_profile(s_.q_cmd, q_goal, vmax, p_.joint_accel_rad_s2);
    s_.phase = ArmMotionStatus::running;
    ++s_.status.goals_accepted;
  }
}

void ArmMotion::run_joints(const CycleInputs& in) noexcept {
  if (s_.phase == ArmMotionStatus::running && hand_retreating(in))
    begin_stop(ArmMotionStatus::aborted, ArmMotionReason::hand_retreat);
  step_joint_profile(s_.joint, in.dt_s, p_.joint_accel_rad_s2, s_.q_cmd, s_.v_cmd);
  speed_m_s_ = 0;
  if (!s_.joint.done) return;
  for (double& v : s_.v_cmd) v = 0;
  if (s_.phase == ArmMotionStatus::stopping) {
    finish(static_cast<ArmMotionStatus::State>(s_.end_state), static_cast<ArmMotionReason>(s_.end_reason));
  } else {
    finish(ArmMotionStatus::reached, ArmMotionReason::none);
  }
}

void ArmMotion::check_path(const CycleInputs& in) noexcept {
  const CartesianPath& path = s_.path;
  const auto& vmax = ik_.velocity_limit();
  for (int n = 0; n < p_.check_samples_per_cycle; ++n) {
    const int k = s_.check_segment;
    if (k >= path.segments()) {  // the whole path solved: accepted, it runs from this cycle
      s_.phase = ArmMotionStatus::running;
      s_.profile = PathProfile{};
      ++s_.status.goals_accepted;
      run(in);
      return;
    }
    const double len = path.length_m[k], ang = path.angle_rad[k];
    double dsig = 1.0;
    if (len > 0) dsig = std::min(dsig, p_.check_step_mm * 1e-3 / len);
    if (ang > 0) dsig = std::min(dsig, p_.check_step_rad / ang);
    // Equal steps: the segment in the fewest steps of at most dsig, so no sliver of a step is
    // left at its end (a joint's rate over a sliver is the IK's own noise, 1e-4 rad, divided
    // by it: a 30.001 mm lift checked in 5 mm steps refused itself as joint_speed).
    dsig = 1.0 / std::ceil(1.0 / dsig - 1e-9);
    double sig = s_.check_sigma + dsig;
    if (sig > 1.0 - 1e-9) sig = 1.0;
    const KDL::Frame target = pose_at(path, k, sig);
    double q[kArmJoints];
    std::memcpy(q, s_.q_check, sizeof(q));
    robot::ArmIk::Result r;
    const auto close = [&] {
      return r.error_m <= p_.tracking_tolerance_mm * 1e-3 && r.error_rad <= p_.tracking_tolerance_rad;
    };
    for (int tries = 0; tries < 3 && !r.converged; ++tries) r = ik_.track(target, std::span<double, kArmJoints>(q, kArmJoints));
    if (!r.converged && !close()) {
      refuse(s_.status.goal_id, ArmMotionReason::unreachable);
      s_.phase = ArmMotionStatus::unreachable;
      s_.status.reason = static_cast<std::uint8_t>(ArmMotionReason::unreachable);
      return;
    }
    if (std::isfinite(path.sd_max[k])) {
      for (int j = 0; j < kArmJoints; ++j) {
        const double rate = std::abs(q[j] - s_.q_check[j]) / (sig - s_.check_sigma) * path.sd_max[k];
        if (rate > p_.joint_speed_fraction * vmax[j]) {
          refuse(s_.status.goal_id, ArmMotionReason::joint_speed);
          s_.phase = ArmMotionStatus::unreachable;
          s_.status.reason = static_cast<std::uint8_t>(ArmMotionReason::joint_speed);
          return;
        }
      }
    }
    std::memcpy(s_.q_check, q, sizeof(q));
    s_.check_sigma = sig;
    if (sig >= 1.0) {
      ++s_.check_segment;
      s_.check_sigma = 0;
    }
  }
}

void ArmMotion::run(const CycleInputs& in) noexcept {
  if (s_.joint_move) {
    run_joints(in);
    return;
  }
  if (s_.phase == ArmMotionStatus::running && s_.lift == 0 && hand_retreating(in)) {
    begin_stop(ArmMotionStatus::aborted, ArmMotionReason::hand_retreat);
  } else if (s_.phase == ArmMotionStatus::running && s_.stop_on == ArmGoal::contact_onset) {
    if (!contact_fresh(in)) {
      begin_stop(ArmMotionStatus::aborted, ArmMotionReason::contact_stale);
    } else {
      // A new onset with a stop finger in contact; or, the hand held in contact since before the
      // start (a detector whose joints read off their reference after the hand's posture changed
      // while it pressed raises no new onset), a stop finger joining that contact.
      const ContactState& c = *in.contact;
      if (c.in_contact == 0) s_.stop_fingers_held = 0;
      const bool onset = c.onsets > s_.onsets_at_start && (c.fingers & s_.stop_fingers) != 0;
      const bool joined =
          c.in_contact != 0 && (c.fingers & s_.stop_fingers & ~s_.stop_fingers_held) != 0;
      if (onset || joined) begin_stop(ArmMotionStatus::stopped_on_contact, ArmMotionReason::none);
    }
  }
  speed_m_s_ = step_profile(s_.path, s_.profile, in.dt_s);
  const KDL::Frame target = pose_at(s_.path, s_.profile.segment, s_.profile.sigma);
  double q[kArmJoints];
  std::memcpy(q, s_.q_cmd, sizeof(q));
  const robot::ArmIk::Result r = ik_.track(target, std::span<double, kArmJoints>(q, kArmJoints));
  ik_error_m_ = r.error_m;
  bool lost = !(r.error_m <= p_.tracking_tolerance_mm * 1e-3 && r.error_rad <= p_.tracking_tolerance_rad);
  const auto& vmax = ik_.velocity_limit();
  for (int j = 0; j < kArmJoints; ++j) lost = lost || std::abs(q[j] - s_.q_cmd[j]) > vmax[j] * in.dt_s;
  if (lost) {  // hold the last good command rather than jump
    finish(ArmMotionStatus::aborted, ArmMotionReason::tracking_lost);
    return;
  }
  for (int j = 0; j < kArmJoints; ++j) {
    s_.v_cmd[j] = (q[j] - s_.q_cmd[j]) / in.dt_s;
    s_.q_cmd[j] = q[j];
  }
  if (s_.profile.done) {
    if (s_.phase == ArmMotionStatus::stopping) {
      finish(static_cast<ArmMotionStatus::State>(s_.end_state), static_cast<ArmMotionReason>(s_.end_reason));
    } else {
      finish(ArmMotionStatus::reached, ArmMotionReason::none);
    }
  }
}

bool ArmMotion::step(const CycleInputs& in) noexcept {
  const Readiness ready = arm_readiness(in);
  speed_m_s_ = 0;
  if (ready == Readiness::ready && (!s_.have_cmd || !s_.arm_was_ready) && !active(s_.phase)) {
    // The first ready state, or ready again after a fault: hold where the arm is.
    for (int j = 0; j < kArmJoints; ++j) {
      s_.q_cmd[j] = in.arm->position_rad[j];
      s_.v_cmd[j] = 0;
    }
    s_.have_cmd = 1;
    if (!s_.have_home) {  // where it started (parked): the joints goals' IK seed
      std::memcpy(s_.home_q, s_.q_cmd, sizeof(s_.home_q));
      s_.have_home = 1;
    }
  }
  s_.arm_was_ready = ready == Readiness::ready;
  if (active(s_.phase) && ready != Readiness::ready) {
    finish(ArmMotionStatus::aborted, ready == Readiness::stale ? ArmMotionReason::arm_stale : ArmMotionReason::arm_fault);
  }
  if (s_.phase == ArmMotionStatus::checking && s_.lift == 0 && hand_retreating(in)) {
    finish(ArmMotionStatus::aborted, ArmMotionReason::hand_retreat);  // nothing moved yet
  } else if (s_.phase == ArmMotionStatus::checking) {
    check_path(in);
  } else if (s_.phase == ArmMotionStatus::running || s_.phase == ArmMotionStatus::stopping) {
    run(in);
  } else {
    for (double& v : s_.v_cmd) v = 0;  // holding
  }
  publish(in);
  return s_.have_cmd != 0;
}

void ArmMotion::publish(const CycleInputs& in) noexcept {
  command_.timestamp_ns = in.now_ns;
  command_.mode = ArmCommand::position;
  for (int j = 0; j < kArmJoints; ++j) {
    command_.position_rad[j] = static_cast<float>(s_.q_cmd[j]);
    command_.velocity_rad_s[j] = static_cast<float>(s_.v_cmd[j]);
  }
  ArmMotionStatus& st = s_.status;
  st.timestamp_ns = in.now_ns;
  st.state = s_.phase;
  const bool moving = s_.phase == ArmMotionStatus::running || s_.phase == ArmMotionStatus::stopping;
  const bool has_path = s_.path.count >= 2 && s_.phase != ArmMotionStatus::refused &&
                        s_.phase != ArmMotionStatus::unreachable && s_.phase != ArmMotionStatus::idle;
  st.segment = static_cast<std::uint8_t>(s_.profile.segment);
  st.progress = has_path ? static_cast<float>(path_progress(s_.path, s_.profile)) : 0.0f;
  if (s_.phase == ArmMotionStatus::checking) st.progress = 0;
  st.distance_to_go_mm = has_path ? static_cast<float>(1000.0 * distance_to_go_m(s_.path, s_.profile)) : 0.0f;
  if (has_path && s_.joint_move) {  // the straight distance, scaled by the profile's progress
    const double done = joint_profile_progress(s_.joint);
    const PathPose& a = s_.path.pose[0];
    const PathPose& b = s_.path.pose[1];
    st.progress = static_cast<float>(done);
    st.distance_to_go_mm = static_cast<float>(
        1000.0 * (1.0 - done) * std::hypot(b.p_m[0] - a.p_m[0], b.p_m[1] - a.p_m[1], b.p_m[2] - a.p_m[2]));
  }
  st.speed_mm_s = moving ? static_cast<float>(1000.0 * speed_m_s_) : 0.0f;
  st.ik_error_mm = static_cast<float>(1000.0 * ik_error_m_);
  // The tool where the arm's readings put it (one forward kinematics a cycle).
  st.tool_measured = 0;
  if (in.arm != nullptr && in.arm->all_finite()) {
    double q[kArmJoints];
    for (int j = 0; j < kArmJoints; ++j) q[j] = in.arm->position_rad[j];
    const KDL::Frame f = ik_.tool_pose(std::span<const double, kArmJoints>(q, kArmJoints));
    for (int a = 0; a < 3; ++a) st.tool_mm[a] = static_cast<float>(1000.0 * f.p(a));
    st.tool_measured = 1;
  }
}

std::size_t ArmMotion::save_state(std::span<std::byte> out) const noexcept {
  if (out.size() < sizeof(MotionState)) return std::numeric_limits<std::size_t>::max();
  std::memcpy(out.data(), &s_, sizeof(MotionState));
  return sizeof(MotionState);
}

bool ArmMotion::load_state(std::span<const std::byte> in) noexcept {
  if (in.size() != sizeof(MotionState)) return false;
  MotionState s;
  std::memcpy(&s, in.data(), sizeof(MotionState));
  if (s.magic != MotionState::kMagic || s.size != sizeof(MotionState) || s.tool >= robot::kToolFrames ||
      s.path.count < 0 || s.path.count > CartesianPath::kMaxPoints) {
    return false;
  }
  s_ = s;
  PathPose o;
  std::memcpy(o.p_m, s_.offset_p, sizeof(o.p_m));
  std::memcpy(o.quat, s_.offset_quat, sizeof(o.quat));
  ik_.set_tool_offset(static_cast<robot::ToolFrame>(s_.tool), to_frame(o));
  return true;
}

}  // namespace crease::arm_motion
