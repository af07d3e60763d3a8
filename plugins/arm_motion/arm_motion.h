// One arm's Cartesian motion controller: goals in, a joint command and a status out, once per
// control cycle. The arm_motion plugin wraps it (ports); tests and crease-bench drive it
// directly.
//
//   ArmMotion m(model, Side::right, params);        // configure time: allocates, may throw
//   m.on_goal(goal, in, world_sheet_or_null);         // RT: a goal popped this cycle
//   if (m.step(in)) write(m.command());               // RT: every cycle
//   publish(m.status());
//
// A goal is refused on arrival (counted per reason, nothing moves) when its content fails
// goal_check.h, a motion is already active (busy), the arm is not ready, a hand tool frame has
// no fresh hand_state, a stop condition has no fresh armed contact_state, a sheet-frame goal
// has no sheet, or a point lies outside the workspace. An accepted goal's path (from the
// tool frame's commanded pose through its points) is then solved ahead, in equal steps at
// most check_step_mm apart, check_samples_per_cycle samples per cycle, while the command
// stays held: a sample without an IK solution inside the joint limits refuses it as
// unreachable, a sample needing a joint faster than joint_speed_fraction of its URDF limit as
// joint_speed. Only then does it run: each cycle the path profile steps (cartesian_path.h)
// and the IK tracks the new pose warm from the last command (ArmIk::track); the command's
// velocity is the step over the cycle.
//
// A joints goal (ArmGoal::joints, one pose in the world or sheet frame) is solved once on
// arrival (ArmIk::solve seeded from the arm's first measured posture, where it started parked:
// the solution on that branch), refused as unreachable without one, and run at once on one
// quintic profile in joint space (joint_profile.h: within joint_speed_fraction of the velocity
// limits and joint_accel_rad_s2): every sample lies within the joint limits, so nothing is
// checked ahead; its tool frame does not follow a straight line. Stops as any motion does.
// A goal in the `measured` frame is relative to the tool frame's measured pose when it arrives
// (the forward kinematics of arm_state's angles): a lift from where the arm is.
// Stop condition (contact_onset): checked every running cycle before the profile steps, so a
// fired condition starts the deceleration (at the goal's stop_accel) in the same cycle; at rest
// the state is stopped_on_contact. A stale or unhealthy contact_state while armed decelerates
// the same way and ends aborted (contact_stale). The hand's controller retreating, inhibited or
// stale (CycleInputs::hand_control, whatever the stop condition) decelerates it the same way
// and ends aborted (hand_retreat); a goal arriving then is refused, one being checked is
// dropped before anything moved; except a lift (path_is_lift, goal_check.h: straight up, the
// orientation kept), the safe direction: accepted, checked and run to its end meanwhile.
// A stale or faulted arm_state aborts at once and holds the last command (the drive is not
// following: the driver commands its own safe state); when the arm is ready again the held
// command is re-seated at the measured angles, so the drive is never sent back to where it
// was before the fault.
// Holding: with nothing running the command is the last one, unchanged, every cycle.
// The whole state is plain data (save_state / load_state: a motion carried across a hot-swap).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/port_types/arm.h"
#include "core/port_types/arm_goal.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/hand_control.h"
#include "plugins/arm_motion/cartesian_path.h"
#include "plugins/arm_motion/goal_check.h"
#include "plugins/arm_motion/joint_profile.h"
#include "plugins/robot_model/arm_ik.h"

namespace crease::arm_motion {

struct MotionParams {
  GoalLimits limits;
  Workspace workspace;
  double arm_state_max_age_s = 0.005;      // arm_state's status older than this: stale
  double hand_state_max_age_s = 0.02;
  double contact_state_max_age_s = 0.005;
  double sheet_state_max_age_s = 0.2;      // (the plugin checks it)
  int check_samples_per_cycle = 1;
  double check_step_mm = 5.0;
  double check_step_rad = 0.05;
  double joint_speed_fraction = 0.9;       // of the URDF's velocity limits
  double joint_accel_rad_s2 = 1.5;         // a joints goal's acceleration limit, every joint
  double tracking_tolerance_mm = 0.01;     // the IK residual a running cycle accepts
  double tracking_tolerance_rad = 1e-5;
  // The trajectory's jerk limits (the goal carries none): along the path (mm/s^3), in rotation
  // (rad/s^3), and a stop's (mm/s^3, >= jerk_mm_s3). 0: acceleration-limited (cartesian_path.h).
  double jerk_mm_s3 = 20000;
  double angular_jerk_rad_s3 = 150;
  double stop_jerk_mm_s3 = 1000000;
  robot::ArmIk::Options ik;
};

// One cycle's inputs; null pointers for ports never written. Stamps: the payloads' own
// timestamp_ns fields (reception or computation times), compared with now_ns.
struct CycleInputs {
  std::int64_t now_ns = 0;
  double dt_s = 0.001;
  const ArmState* arm = nullptr;
  const HandState* hand = nullptr;
  const ContactState* contact = nullptr;
  // The hand's command stage (force_controller), when wired: its retreat, an inhibit, or its
  // status older than hand_state_max_age_s stops the arm (the hand lets go: the arm must not
  // drag on). Null: not watched.
  const HandControlStatus* hand_control = nullptr;
};

// Everything a motion is, as plain bytes (what a hot-swap carries).
struct MotionState {
  static constexpr std::uint32_t kMagic = 0x314d5241;  // "ARM1"
  std::uint32_t magic = kMagic;
  std::uint32_t size = 0;
  double q_cmd[robot::kArmJoints] = {};
  double v_cmd[robot::kArmJoints] = {};
  std::uint8_t have_cmd = 0;
  std::uint8_t arm_was_ready = 0;
  std::uint8_t phase = ArmMotionStatus::idle;
  std::uint8_t end_state = 0;   // what a stop ends in (stopped_on_contact or aborted)
  std::uint8_t end_reason = 0;
  std::uint8_t tool = 0;
  std::uint8_t stop_on = 0;
  std::uint8_t stop_fingers = 0;
  std::uint8_t stop_fingers_held = 0;  // of stop_fingers, those in a contact held since the start
  std::uint8_t lift = 0;        // a lift (goal_check.h): the hand's retreat does not stop it
  std::uint8_t joint_move = 0;  // the motion is a joints goal's (joint), not the path's
  std::uint8_t have_home = 0;
  double home_q[robot::kArmJoints] = {};  // the first measured posture: a joints goal's IK seed
  JointProfile joint;
  std::uint64_t onsets_at_start = 0;
  double offset_p[3] = {};             // flange -> tool, metres
  double offset_quat[4] = {0, 0, 0, 1};
  CartesianPath path;
  PathProfile profile;
  int check_segment = 0;
  double check_sigma = 0;
  double q_check[robot::kArmJoints] = {};
  ArmMotionStatus status;
};

class ArmMotion {
 public:
  // Non-RT. MODEL is read here only. Throws crease::ConfigError (the IK's rest posture).
  ArmMotion(const robot::RobotModel& model, robot::Side side, const MotionParams& params);

  // RT. A goal popped this cycle (before step). WORLD_SHEET: the sheet frame (metres) when the
  // goal is in the sheet frame and a fresh sheet_state gave one, else null.
  void on_goal(const ArmGoal& goal, const CycleInputs& in, const KDL::Frame* world_sheet) noexcept;
  // RT. One cycle. True when command() is to be written (from the first ready arm_state on).
  bool step(const CycleInputs& in) noexcept;

  [[nodiscard]] const ArmCommand& command() const noexcept { return command_; }
  [[nodiscard]] const ArmMotionStatus& status() const noexcept { return s_.status; }
  [[nodiscard]] const MotionState& state() const noexcept { return s_; }
  [[nodiscard]] robot::ArmIk& ik() noexcept { return ik_; }

  // RT-safe. Bytes written, or SIZE_MAX when OUT is too small.
  std::size_t save_state(std::span<std::byte> out) const noexcept;
  // RT-safe. False (and nothing changed) for bytes that are not a MotionState of this build.
  bool load_state(std::span<const std::byte> in) noexcept;

 private:
  enum class Readiness : std::uint8_t { ready, stale, fault };
  [[nodiscard]] Readiness arm_readiness(const CycleInputs& in) const noexcept;
  [[nodiscard]] bool contact_fresh(const CycleInputs& in) const noexcept;
  [[nodiscard]] bool hand_retreating(const CycleInputs& in) const noexcept;
  void refuse(std::uint32_t id, ArmMotionReason r) noexcept;
  void finish(ArmMotionStatus::State st, ArmMotionReason r) noexcept;
  void begin_stop(ArmMotionStatus::State end, ArmMotionReason r) noexcept;
  void check_path(const CycleInputs& in) noexcept;
  void run(const CycleInputs& in) noexcept;
  void run_joints(const CycleInputs& in) noexcept;
  void publish(const CycleInputs& in) noexcept;

  MotionParams p_;
  robot::ArmIk ik_;
  MotionState s_;
  ArmCommand command_;
  double ik_error_m_ = 0;
  double speed_m_s_ = 0;
};

}  // namespace crease::arm_motion
