// The folding sequence's machine: runs the tables of states.h against one cycle's sensing and
// emits the commands of the states it enters. A hierarchical state machine: entering a state
// enters its superstates from the common ancestor down and its initial children, leaving one
// runs the exit actions from the leaf up; a transition is one row of states.h, at most one per
// cycle. Its whole run-time state is `Memory`, one plain struct (copied whole at a hot-swap).
//
// Each cycle (RT, no allocation): the operator's command, if any, then the fault checks (in
// `fold`), then the rows of the active states from the innermost outwards. A paused machine
// checks faults but fires no other row and counts no time; in step mode it pauses before each
// transition other than an abort (`step` makes that one transition, `resume` goes on). Pausing
// by the operator stops the arms and holds the hands that press; resuming re-enters the state
// (its commands sent again from where the robot is).
//
// The machine speaks of two roles, not sides: the fixing hand fixates the sheet (and shifts it,
// unless the fold file gives the shift to the pinching hand: `shift.hand`), the pinching hand
// pinches, bends, swipes and hardens. Seed 000 (Fig. 7) gives the right hand (taxels, rubber) the
// shift and the fixing, the left (PST, fabric) the pinching; a fold file may swap them
// (`hands.pinching`) and the plugin binds each role to that side's ports.
#pragma once

#include <cstdint>

#include "core/port_types/arm_goal.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand_control.h"
#include "core/port_types/hand_goal.h"
#include "core/port_types/keypoints.h"
#include "core/port_types/sequence_status.h"
#include "core/port_types/sheet_state.h"
#include "plugins/fold_sequence/fold_spec.h"
#include "plugins/fold_sequence/sheet_geometry.h"
#include "plugins/fold_sequence/states.h"

namespace crease::fold {

inline constexpr int kFixing = 0;    // the role index of Sensing's and Outbox's arrays
inline constexpr int kPinching = 1;

// The side (0 right, 1 left) that plays ROLE in fold F.
[[nodiscard]] inline int side_of_role(const FoldSpec& f, int role) noexcept {
  return role == kPinching ? f.pinching_side : 1 - f.pinching_side;
}

// How a retreat goal (a lift, a park) stands, from arm_motion's status: still under way (or its
// status not yet about it), reached, ended short for good (a refusal or abort that a retry
// cannot mend: unreachable, outside the workspace, a bad goal, the drive in fault), or ended
// short for a reason that may pass (the arm's state stale, the hand's controller retreating,
// busy): sent again.
enum class RetreatEnd : std::uint8_t { pending, reached, gave_up, retry };
[[nodiscard]] RetreatEnd retreat_end(const ArmMotionStatus* a, std::uint32_t id) noexcept;
// Why arm_motion ended goal ID (an ArmMotionReason): its refusal when it was refused, else the
// reason on the status. A is not null.
[[nodiscard]] inline std::uint8_t end_reason(const ArmMotionStatus& a, std::uint32_t id) noexcept {
  return a.last_refused_id == id ? a.last_refusal : a.reason;
}
inline constexpr double kRetryS = 0.1;  // a retreat goal sent again at most this often

// One cycle's sensing; a null pointer: never written. Timestamps are compared with now_ns.
struct Sensing {
  std::int64_t now_ns = 0;
  const ArmMotionStatus* arm[2] = {nullptr, nullptr};
  const HandControlStatus* hand[2] = {nullptr, nullptr};
  const ContactState* contact[2] = {nullptr, nullptr};
  const SheetState* sheet = nullptr;
  const Keypoints* keypoints = nullptr;  // the markers' key-points of the last vision frame
};

// What one cycle sends, in order per port (the plugin pushes them onto its queues).
struct Outbox {
  static constexpr int kPerPort = 2;
  ArmGoal arm[2][kPerPort];
  int arm_count[2] = {0, 0};
  HandGoal hand[2][kPerPort];
  int hand_count[2] = {0, 0};
  SheetCreaseEvent crease;
  bool has_crease = false;
  SheetMemorizeEvent memorize;
  bool has_memorize = false;
  bool overflow = false;  // a state sent more than kPerPort to one port (a bug of the tables)
  // The retreat sent role r's lift or park again: why the last one ended short (an
  // ArmMotionReason), kNoRetry when it did not.
  static constexpr std::uint8_t kNoRetry = 0xff;
  std::uint8_t retried[2] = {kNoRetry, kNoRetry};
  std::uint8_t gave_up[2] = {kNoRetry, kNoRetry};  // ... or ended it for good, and why
  bool joints_park[2] = {false, false};  // ... or sent the park again in joint space
  bool park_lift[2] = {false, false};    // ... or lifted the hand before that (park_lift_mm)
  void clear() noexcept {
    arm_count[0] = arm_count[1] = hand_count[0] = hand_count[1] = 0;
    has_crease = has_memorize = overflow = false;
    retried[0] = retried[1] = gave_up[0] = gave_up[1] = kNoRetry;
    joints_park[0] = joints_park[1] = park_lift[0] = park_lift[1] = false;
  }
};

enum class Command : std::uint8_t { none = 0, start = 1, pause = 2, resume = 3, abort = 4, step = 5 };

struct Memory {
  static constexpr std::uint32_t kTag = 0x464f4c44;  // "FOLD"
  // 2: grasp/shape; 3: fixate_layer/lay, refixate/slide_out, swipe/release, withdraw; 4: the
  // retreat's retries (arm_sent_ns, gave_up_id, park_joints); 5: park_lift_mm (the lift before a
  // park in joint space, halved while out of reach); 6: aborted_from; 7: pinch_off_since_ns;
  // 8: held_frame; 9: shift/check, slides; 10: press_held, press_uv; 11: flap_seen_since_ns
  static constexpr std::uint32_t kVersion = 11;
  std::uint32_t tag = kTag;
  std::uint32_t version = kVersion;
  std::uint64_t spec_hash = 0;      // the fold this memory belongs to (name and via points)
  S leaf = S::idle;
  std::uint8_t via = 0;
  std::uint8_t slides = 0;          // the shift's slides so far
  std::uint8_t paused = 0;          // by the operator (arms stopped): resume re-enters the leaf
  std::uint8_t step_mode = 0;
  std::uint8_t start_pending = 0;
  std::uint8_t self_entry = 0;      // the entry running is a self-transition's
  Reason last_reason = Reason::none;
  Reason abort_reason = Reason::none;
  // The leaf the abort came from, and the pinching arm's path segment then (its status's): the
  // retreat's lift backs out of a grasp the way it went in.
  static constexpr std::uint8_t kNoSegment = 0xff;
  S aborted_from = S::idle;
  std::uint8_t aborted_segment = kNoSegment;
  std::int16_t last_row = -1;       // index into all_rows() of the last transition; -1 none
  std::int16_t gate_row = -1;       // step mode: the transition held until `step`
  std::uint32_t transitions = 0;
  std::uint32_t aborts = 0;
  std::int64_t last_ns = 0;         // the previous cycle's time
  std::int64_t leaf_since_ns = 0;
  std::int64_t elapsed_ns[kStateCount] = {};  // time in each active state, pauses not counted
  std::int64_t vision_bad_since_ns = 0;       // 0: the sheet is seen
  std::int64_t pinch_off_since_ns = 0;        // 0: the tracked grasp point is on the pinch's way
  std::int64_t flap_seen_since_ns = 0;        // 0: the laid layer's printed face not seen
  std::uint32_t next_id = 1;
  std::uint32_t arm_id[2] = {0, 0};   // this state's arm goals (0: none)
  std::uint32_t hand_id[2] = {0, 0};  // this state's hand goals
  std::uint64_t hand_refused0[2] = {0, 0};  // goals_refused when that hand goal was sent
  std::uint64_t inhibits0[2] = {0, 0};      // the hands' inhibits counters when the fold began
  HandMode hand_mode[2] = {HandMode::hold, HandMode::hold};  // the mode last asked of each hand
  std::uint8_t force_fingers[2] = {0, 0};  // the last force goal of each hand, for a resume
  float force_n[2] = {0, 0};
  std::uint8_t held_by_pause[2] = {0, 0};  // 1: the pause put this pressing hand on hold
  std::uint8_t arm_has_target[2] = {0, 0};
  std::uint8_t arm_frame[2] = {0, 0};
  std::uint8_t arm_tool[2] = {0, 0};
  std::int64_t arm_sent_ns[2] = {0, 0};  // when the last move goal was sent
  std::uint32_t gave_up_id[2] = {0, 0};  // the last retreat goal reported as ended for good
  // The park out of reach on a line (joints_park_due): kParkLifting while the hand rises by
  // park_lift_mm, kParkJoints once the park was sent again in joint space.
  static constexpr std::uint8_t kParkLifting = 2, kParkJoints = 1;
  std::uint8_t park_joints[2] = {0, 0};
  // The lift now tried before the park in joint space (mm): park_lift_mm, halved each time it
  // is out of reach (unreachable, joint_speed) down to kMinParkLiftMm, then the park as it is.
  static constexpr double kMinParkLiftMm = 20.0;
  double park_lift_mm[2] = {0, 0};
  double arm_target[2][3] = {};       // the last move goal's target (its frame)
  double arm_orientation[2][4] = {};
  std::uint32_t crease_count0 = 0;    // sheet_state's creases when the crease was sent
  std::uint64_t sheet_step0 = 0;      // sheet_state's step when the memorize was sent
  double harden_a[2] = {}, harden_b[2] = {};  // the hardening stroke (sheet mm), from the model
  // The tracked sheet's frame when the bend began (frame_held 0: there was none). From the lay
  // on the near half lies under the bent layer, its markers hidden, and the model's frame
  // drifts while the fixing hand holds the world's half still (trials: 12-31 mm, the world's
  // 1.5-10 mm): the goals of the lay, the refixation, the swipe and the hardening are put into
  // the world by this frame (uses_held_frame).
  std::uint8_t frame_held = 0;
  SheetFrame held_frame{};
  // The laid layer's point (u, v) under the fixing tool as the refixation's press began, in the
  // tracked sheet (press_held 0: the model had none of the layer there): what that press holds.
  std::uint8_t press_held = 0;
  double press_uv[2] = {0, 0};
};

class Machine {
 public:
  explicit Machine(const FoldSpec& spec) noexcept;

  // RT. Takes the operator's command (applied in the next step()).
  void command(Command c) noexcept { command_ = c; }
  // RT. One cycle: commands, faults, rows; the entered states' commands into out (cleared first).
  void step(const Sensing& in, Outbox& out) noexcept;
  // RT. A fault found outside the machine (a full command queue): abort with `r` when folding.
  void fail(Reason r) noexcept { external_fault_ = r; }

  [[nodiscard]] const Memory& memory() const noexcept { return m_; }
  // False (and nothing changed) when `saved` is not a memory of this fold and version.
  [[nodiscard]] bool restore(const Memory& saved) noexcept;
  // RT. The status port's value now.
  void fill_status(SequenceStatus& s, std::int64_t now_ns) const noexcept;
  [[nodiscard]] SequenceStatus::Phase phase() const noexcept;
  // RT. While the pinch holds the sheet (the bend from the pinch on, the lay, the refixation):
  // the grasp point (sheet mm, the fold file's grasp_at_mm) and where the pinching arm's readings
  // put the pinching tool (world mm, arm_motion's status). The model takes it as a target
  // (`target_points`): the robot knows where its fingers hold the sheet when the hand hides the
  // flap's markers from the cameras, or the fold turns them away. False otherwise.
  [[nodiscard]] bool grasp_target(const Sensing& in, double world_mm[3],
                                  double sheet_mm[2]) const noexcept;
  // RT. While the fixing hand presses both layers (refixate/press, the swipe, the hardening,
  // the memorize): the laid layer's point it holds (sheet mm, Memory::press_uv) and where the
  // fixing arm's readings put the fixing tool (world mm). The laid layer shows the cameras its
  // unprinted back, and once the pinch lets go nothing else tells the model where it lies.
  // False otherwise.
  [[nodiscard]] bool press_target(const Sensing& in, double world_mm[3],
                                  double sheet_mm[2]) const noexcept;

 private:
  // machine.cpp: the engine.
  void apply_command(const Sensing& in, Outbox& out) noexcept;
  void go(S to, Reason r, int row, const Sensing& in, Outbox& out) noexcept;
  void count_time(std::int64_t now_ns) noexcept;
  [[nodiscard]] bool timed_out(S owner) const noexcept;
  // conditions.cpp: events, guards, faults.
  [[nodiscard]] bool holds(Ev ev, S owner, const Sensing& in) const noexcept;
  [[nodiscard]] bool passes(Guard g, const Sensing& in) const noexcept;
  [[nodiscard]] Reason fault(const Sensing& in) noexcept;  // Reason::none when all is well
  // spec_.pinch_lost_mm's check on the tracked sheet SH (conditions.cpp): Reason::pinch_lost when
  // its grasp point is off the pinch's way (bend, lay), Reason::fold_lost when, the pinch let go,
  // it is off where the layer was laid (swipe, harden); Reason::none when on it, outside those
  // states, or not judged (JUDGED false: a model state from within the state's first 150 ms,
  // which may lag the state's motion; the time off the way runs on through it).
  [[nodiscard]] Reason grasp_off(const SheetState& sh, bool& judged) const noexcept;
  // spec_.flap_seen_points's check (conditions.cpp): from the lay on, the laid layer's printed
  // face in view, in every key-point frame for flap_seen_s (Memory::flap_seen_since_ns).
  [[nodiscard]] bool flap_open(const Sensing& in) noexcept;
  [[nodiscard]] double slide_length(const Sensing& in, double d_sheet[2],
                                    double d_world[2] = nullptr) const noexcept;
  // actions.cpp: entry and exit actions, the goals.
  void enter(S s, const Sensing& in, Outbox& out) noexcept;
  void exit(S s, const Sensing& in, Outbox& out) noexcept;
  void stop_for_pause(Outbox& out) noexcept;
  // abort/lift, abort/park, each cycle without a transition: an arm whose lift or park ended
  // short for a reason that may pass (retreat_end) gets it again, at most every kRetryS; a
  // hand whose controller retreats is opened again with it (its latch cleared, the park taken).
  void retry_retreat(const Sensing& in, Outbox& out) noexcept;
  // abort/lift, abort/park, each cycle before the rows: a retreat goal that ended for good is
  // reported once (Outbox::gave_up), since the arm stays where that left it.
  void report_retreat(const Sensing& in, Outbox& out) noexcept;
  // abort/park: role S's park, a straight line there, was refused as out of reach (unreachable,
  // joint_speed: a wrist the fold turned) and has not been sent in joint space yet (ArmGoal::joints).
  [[nodiscard]] bool joints_park_due(int s, const Sensing& in) const noexcept;
  // abort/park, role S: a park out of reach on a line lifted by park_lift_mm (halved while out of
  // reach), then sent in joint space. True when it took this cycle's turn of role S's retreat.
  bool park_out_of_reach(int s, const Sensing& in, Outbox& out) noexcept;
  void arm_move(int side, std::uint8_t tool, std::uint8_t frame, const double p[3], const double q[4],
                const MotionLimits& lim, std::uint8_t stop_fingers, Outbox& out) noexcept;  // 0: no stop
  // One motion through the n points of path_mm (1..ArmGoal::kMaxPoints), the tool turned to
  // orientation[k] at point k.
  void arm_path(int side, std::uint8_t tool, std::uint8_t frame, int n, const double (*path_mm)[3],
                const double (*orientation)[4], const MotionLimits& lim, std::uint8_t stop_fingers, Outbox& out) noexcept;
  void arm_stop(int side, Outbox& out) noexcept;
  void arm_lift(int side, double lift_mm, Outbox& out) noexcept;
  void arm_park(int side, Outbox& out, bool joints = false) noexcept;
  // The abort's lift of the pinching hand when the abort came from the grasp's reach or pinch:
  // back along the reach path's points it had passed (a reach aborted on its way: those before
  // the segment it ran) to above_mm (false: not from there, nothing sent). RT.
  bool back_out_of_grasp(Outbox& out) noexcept;
  // ... and when it came from the bend or the lay: back through the via points it had passed
  // (the last one first; every other one when they do not fit one goal, the first always), to
  // above_mm and back through above_via: the way it came, which the park line ends (false: not
  // from there, or still by the grasp: nothing sent). RT.
  bool back_out_of_bend(const Sensing& in, Outbox& out) noexcept;
  // above_via point K in the sheet frame the goal is sent in (a `frame: world` point put into the
  // tracked sheet's frame of IN; false without one). RT.
  [[nodiscard]] bool above_via_in_sheet(int k, const Sensing& in, double p[3],
                                        double q[4]) const noexcept;
  // The via points the pinch had passed when the fold aborted in the bend or the lay (0: not from
  // there).
  [[nodiscard]] int bend_passed() const noexcept;
  // The pinching tool to P (sheet frame) at contact speed, turned as the last via point: the
  // pinch as the bend laid it (lay, withdraw).
  // Via point K's orientation (sheet frame), turned back about the vertical by what the bend's
  // heading at the held frame exceeds the fold file's yaw range by (FoldSpec::bend_yaw_*).
  void via_orientation(int k, double q[4]) const noexcept;
  void pinch_as_laid(const double p[3], Outbox& out) noexcept;
  // STIFFNESS (N m/rad, 20 joints) or nullptr: the controller's stiffness kept; RAMP_S (s) < 0:
  // the file's ramp_s.
  void hand_posture(int side, const float* target_rad, const Sensing& in, Outbox& out,
                    const float* stiffness = nullptr, double ramp_s = -1) noexcept;
  void hand_force(int side, std::uint8_t fingers, double force_n, const Sensing& in, Outbox& out) noexcept;
  void hand_hold(int side, const Sensing& in, Outbox& out) noexcept;
  void approach(int side, const ContactStep& c, Outbox& out) noexcept;     // above c.at
  void descend(int side, const ContactStep& c, Outbox& out) noexcept;      // down to c.at, stop on contact
  void push_hand(int side, HandGoal g, const Sensing& in, Outbox& out) noexcept;

  // State S sends its sheet-frame goals as world goals by Memory::held_frame (when one was held).
  [[nodiscard]] static bool uses_held_frame(S s) noexcept;

  const FoldSpec& spec_;
  Memory m_;
  Command command_ = Command::none;
  Reason external_fault_ = Reason::none;
  Reason detected_ = Reason::none;  // the fault found this cycle (the fault row's reason)
  // Which input the fault came from, e.g. "contact_r unhealthy" (a string literal; null: none).
  // detail_: this cycle's; abort_detail_: the one that started the abort (not kept by a swap).
  const char* detail_ = nullptr;
  const char* abort_detail_ = nullptr;
};

// A hash of what a Memory depends on in the fold (its name, via points, sides), for load_state.
[[nodiscard]] std::uint64_t spec_hash(const FoldSpec& f) noexcept;

}  // namespace crease::fold
