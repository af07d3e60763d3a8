// The folding sequence's states and transitions, as tables (seed 000 Fig. 7, steps a-h):
//
//   idle ─start─► fold ─────────────────────────────────────────────────────────► done
//                  shift(a) grasp(b) bend(c) fixate_layer(d) refixate(e) swipe(f) harden(g) finish(h)
//                  └─ any fault, a timeout ─► abort: stop ► open ► lift ► reopen ► park ─► aborted
//
// A state is a leaf or a superstate (its `initial` child is entered with it). A transition row
// belongs to a state and fires when its event holds and its guard passes; rows are tried from
// the innermost state outwards, so a superstate's rows (fold's faults, every state's timeout)
// apply to all of its children. Every state has a timeout (its row `timeout`), every state of
// `fold` reaches `abort`. Plain constant data: the machine (machine.h) runs it, the Graphviz
// dump (graph.h) prints it.
#pragma once

#include <cstdint>
#include <string_view>

#include "plugins/fold_sequence/fold_spec.h"

namespace crease::fold {

// clang-format off
enum class S : std::uint8_t {
  root,
  idle,
  fold,
  shift, shift_approach, shift_contact, shift_press, shift_slide, shift_check,
  grasp, grasp_open, grasp_lift, grasp_park, grasp_fix_approach, grasp_fix_contact, grasp_fixate, grasp_shape, grasp_above,
  grasp_reach, grasp_pinch,
  bend, bend_crease, follow_via,
  fixate_layer, layer_lay,
  refixate, refix_slide_out, refix_open, refix_lift, refix_approach, refix_contact, refix_press,
  swipe, swipe_release, swipe_withdraw, swipe_open, swipe_lift, swipe_approach, swipe_contact, swipe_press, swipe_slide,
  harden, harden_open, harden_lift, harden_approach, harden_contact, harden_press, harden_slide,
  finish, finish_memorize, finish_open, finish_lift, finish_park,
  done,
  abort, abort_stop, abort_open, abort_lift, abort_reopen, abort_park,
  aborted,
  count
};
// clang-format on
inline constexpr int kStateCount = static_cast<int>(S::count);
static_assert(kStateCount <= kStates, "FoldSpec keeps one timeout per state");

// What makes a row fire: a condition of the sensing against what the state commanded.
// clang-format off
enum class Ev : std::uint8_t {
  start,          // the operator's start
  timeout,        // the row's state has been in it longer than its timeout
  fault,          // a fault of the sensing (Reason says which); fold's rows only
  arm_fix_reached, arm_pin_reached, arms_reached,   // the state's arm goal(s) reached
  arm_fix_contact, arm_pin_contact,                 // stopped on a contact onset
  arm_fix_missed, arm_pin_missed,                   // a contact descent reached its depth untouched
  hand_fix_settled, hand_pin_settled,               // force settled on the state's force goal
  hand_fix_posed, hand_pin_posed, hands_posed,      // the state's posture goal done
  // The same of the shift's hand (the fold file's shift.hand: the fixing one, or the pinching
  // one, the rubber-covered hand that shifts in seed 000 Fig. 7a).
  arm_shift_reached, arm_shift_contact, arm_shift_missed, hand_shift_settled,
  pinched,        // the pinching hand's closing ended with the pinch fingers squeezing (force_n)
  crease_acked,   // sheet_state carries one crease more than when the state began
  sheet_settled,  // a sheet_state taken settle_s or more after the state began (the model caught up)
  memorized,      // a sheet_state newer than the memorize request (the model consumed it)
  stopped,        // abort: both hands took the hold goal (or retreat on their own, or refused
                  // it), and neither arm runs a motion
  arms_done,      // abort: both arms' goals reached, or ended short for good (retreat_end;
                  // one short for a reason that may pass is sent again, retry_retreat)
  always,         // at once (a completion)
};
// clang-format on

// clang-format off
enum class Guard : std::uint8_t {
  none,
  ready,           // start: every controller answers (fresh; contact healthy; the hand commanded), the sheet is seen
  slide_needed,    // shift: the corner is further than the tolerance from its target
  slide_too_long,  // shift: longer than max_slide_mm
  slide_again,     // shift: slide_needed, and fewer than max_slides slides so far
  shifted_by_fixing,    // shift: the corner within the tolerance, and the fixing hand shifted (it stays and fixates)
  shifted_by_pinching,  // shift: the same, and the pinching hand shifted (it lets go, the fixing one comes)
  fixing_armed,    // the hand's contact_state is armed, healthy: a contact motion may start
  pinching_armed,
  shift_armed,     // ... the shift's hand's
  more_via,        // bend: via points left
  last_via,
};
// clang-format on

// Why the machine left a state: the last transition's reason, the abort's reason.
enum class Reason : std::uint8_t {
  none,
  started,
  condition,  // the row's event (its `why` text)
  timeout,
  device_fault,    // a controller's status stale, a hand or arm fault, contact_state unhealthy
  vision_lost,     // sheet_state stale or without observations longer than the bound
  force_limit,     // a fingertip over the force controller's limit
  unreachable,     // arm_motion refused a goal as unreachable (or its joint speed)
  goal_refused,    // arm_motion or a force controller refused a goal for another reason
  motion_aborted,  // arm_motion aborted the state's motion
  slide_out_of_range,
  no_sheet,      // a state needed the sheet's pose and there was none
  command_lost,  // a command queue was full
  operator_abort,
  no_contact,   // a contact descent reached its depth (below the surface) without a contact
  pinch_lost,   // the tracked grasp point left the pinching tool's way (bend, lay)
  fold_lost,    // ... or, the pinch let go, left where the layer was laid (swipe, harden)
  shift_short,  // the corner still off its target after max_slides slides (the finger slipping over
                // the sheet)
  count
};
[[nodiscard]] const char* reason_name(Reason r) noexcept;

struct StateInfo {
  S id;
  S parent;
  S initial;         // a superstate's first child; the state itself for a leaf
  const char* name;  // its path element
};

struct Row {
  S from;
  Ev ev;
  Guard guard;
  S to;
  Reason reason;     // the transition's reason (condition: its event; fault: the detector's)
  const char* why;   // shown as the last transition's reason
};

[[nodiscard]] const StateInfo& state_info(S s) noexcept;
[[nodiscard]] inline bool is_leaf(S s) noexcept { return state_info(s).initial == s; }
[[nodiscard]] int depth(S s) noexcept;  // root 0, idle 1, fold/shift 2, ...
[[nodiscard]] bool is_within(S s, S ancestor) noexcept;  // s == ancestor or below it
// From the lay to the hardening's end (fixate_layer, refixate, swipe, harden): the bent layer lies
// on the stack, its unprinted back to the cameras.
[[nodiscard]] bool layer_laid(S s) noexcept;
// The rows, every state's in table order; `rows_of` the ones of one state.
struct RowSpan {
  const Row* begin;
  const Row* end;
};
[[nodiscard]] RowSpan all_rows() noexcept;
[[nodiscard]] RowSpan rows_of(S s) noexcept;
// The state named by a slash path below root ("fold/bend/follow_via"), or S::count.
[[nodiscard]] S state_by_path(std::string_view path) noexcept;
// Writes the path of s ("fold/bend/follow_via[3]" with via >= 0 for follow_via) into out
// (NUL-terminated, truncated to n - 1). RT-safe.
void write_path(S s, int via, char* out, std::size_t n) noexcept;

}  // namespace crease::fold
