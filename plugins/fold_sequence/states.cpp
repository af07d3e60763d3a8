#include "plugins/fold_sequence/states.h"

#include <array>
#include <cstring>

namespace crease::fold {
namespace {

constexpr std::array<StateInfo, kStateCount> kStatesTable = {{
    {S::root, S::root, S::idle, ""},
    {S::idle, S::root, S::idle, "idle"},
    {S::fold, S::root, S::shift, "fold"},
    {S::shift, S::fold, S::shift_approach, "shift"},
    {S::shift_approach, S::shift, S::shift_approach, "approach"},
    {S::shift_contact, S::shift, S::shift_contact, "contact"},
    {S::shift_press, S::shift, S::shift_press, "press"},
    {S::shift_slide, S::shift, S::shift_slide, "slide"},
    {S::shift_check, S::shift, S::shift_check, "check"},
    {S::grasp, S::fold, S::grasp_fixate, "grasp"},
    {S::grasp_open, S::grasp, S::grasp_open, "open"},
    {S::grasp_lift, S::grasp, S::grasp_lift, "lift"},
    {S::grasp_park, S::grasp, S::grasp_park, "park"},
    {S::grasp_fix_approach, S::grasp, S::grasp_fix_approach, "fix_approach"},
    {S::grasp_fix_contact, S::grasp, S::grasp_fix_contact, "fix_contact"},
    {S::grasp_fixate, S::grasp, S::grasp_fixate, "fixate"},
    {S::grasp_shape, S::grasp, S::grasp_shape, "shape"},
    {S::grasp_above, S::grasp, S::grasp_above, "above"},
    {S::grasp_reach, S::grasp, S::grasp_reach, "reach"},
    {S::grasp_pinch, S::grasp, S::grasp_pinch, "pinch"},
    {S::bend, S::fold, S::bend_crease, "bend"},
    {S::bend_crease, S::bend, S::bend_crease, "crease"},
    {S::follow_via, S::bend, S::follow_via, "follow_via"},
    {S::fixate_layer, S::fold, S::layer_lay, "fixate_layer"},
    {S::layer_lay, S::fixate_layer, S::layer_lay, "lay"},
    {S::refixate, S::fold, S::refix_slide_out, "refixate"},
    {S::refix_slide_out, S::refixate, S::refix_slide_out, "slide_out"},
    {S::refix_open, S::refixate, S::refix_open, "open"},
    {S::refix_lift, S::refixate, S::refix_lift, "lift"},
    {S::refix_approach, S::refixate, S::refix_approach, "approach"},
    {S::refix_contact, S::refixate, S::refix_contact, "contact"},
    {S::refix_press, S::refixate, S::refix_press, "press"},
    {S::swipe, S::fold, S::swipe_release, "swipe"},
    {S::swipe_release, S::swipe, S::swipe_release, "release"},
    {S::swipe_withdraw, S::swipe, S::swipe_withdraw, "withdraw"},
    {S::swipe_open, S::swipe, S::swipe_open, "open"},
    {S::swipe_lift, S::swipe, S::swipe_lift, "lift"},
    {S::swipe_approach, S::swipe, S::swipe_approach, "approach"},
    {S::swipe_contact, S::swipe, S::swipe_contact, "contact"},
    {S::swipe_press, S::swipe, S::swipe_press, "press"},
    {S::swipe_slide, S::swipe, S::swipe_slide, "slide"},
    {S::harden, S::fold, S::harden_open, "harden"},
    {S::harden_open, S::harden, S::harden_open, "open"},
    {S::harden_lift, S::harden, S::harden_lift, "lift"},
    {S::harden_approach, S::harden, S::harden_approach, "approach"},
    {S::harden_contact, S::harden, S::harden_contact, "contact"},
    {S::harden_press, S::harden, S::harden_press, "press"},
    {S::harden_slide, S::harden, S::harden_slide, "slide"},
    {S::finish, S::fold, S::finish_memorize, "finish"},
    {S::finish_memorize, S::finish, S::finish_memorize, "memorize"},
    {S::finish_open, S::finish, S::finish_open, "open"},
    {S::finish_lift, S::finish, S::finish_lift, "lift"},
    {S::finish_park, S::finish, S::finish_park, "park"},
    {S::done, S::root, S::done, "done"},
    {S::abort, S::root, S::abort_stop, "abort"},
    {S::abort_stop, S::abort, S::abort_stop, "stop"},
    {S::abort_open, S::abort, S::abort_open, "open"},
    {S::abort_lift, S::abort, S::abort_lift, "lift"},
    {S::abort_reopen, S::abort, S::abort_reopen, "reopen"},
    {S::abort_park, S::abort, S::abort_park, "park"},
    {S::aborted, S::root, S::aborted, "aborted"},
}};

constexpr bool table_in_order() {
  for (int i = 0; i < kStateCount; ++i)
    if (static_cast<int>(kStatesTable[static_cast<std::size_t>(i)].id) != i) return false;
  return true;
}
static_assert(table_in_order(), "kStatesTable lists the states in S's order");

constexpr Reason C = Reason::condition;

// Rows by state, in S's order (rows_of relies on it). The first row whose event holds and whose
// guard passes fires; a state's rows come before its superstates'.
constexpr Row kRows[] = {
    {S::idle, Ev::start, Guard::ready, S::fold, Reason::started, "start"},

    {S::fold, Ev::fault, Guard::none, S::abort, Reason::device_fault,
     "fault"},  // reason: the detector's
    {S::fold, Ev::timeout, Guard::none, S::abort, Reason::timeout, "state timeout"},

    // clang-format off
    {S::shift_approach, Ev::arm_shift_reached, Guard::shift_armed, S::shift_contact, C, "shifting tool above the press point"},
    {S::shift_contact, Ev::arm_shift_contact, Guard::none, S::shift_press, C, "shifting hand touches the sheet"},
    {S::shift_contact, Ev::arm_shift_missed, Guard::none, S::abort, Reason::no_contact, "no contact at the descent's depth"},
    {S::shift_press, Ev::hand_shift_settled, Guard::slide_too_long, S::abort, Reason::slide_out_of_range,
     "slide longer than max_slide_mm"},
    {S::shift_press, Ev::hand_shift_settled, Guard::slide_needed, S::shift_slide, C, "shifting force settled"},
    {S::shift_press, Ev::hand_shift_settled, Guard::shifted_by_fixing, S::grasp_fixate, C, "corner already in reach"},
    {S::shift_press, Ev::hand_shift_settled, Guard::shifted_by_pinching, S::grasp_open, C, "corner already in reach"},
    {S::shift_slide, Ev::arm_shift_reached, Guard::none, S::shift_check, C, "slide ended"},
    // Shifted is what the tracked sheet says once the model has caught up, not the arm's arrival:
    // a finger that slipped over the sheet left the corner short (the rest is slid again).
    {S::shift_check, Ev::sheet_settled, Guard::shifted_by_fixing, S::grasp_fixate, C, "sheet shifted"},
    {S::shift_check, Ev::sheet_settled, Guard::shifted_by_pinching, S::grasp_open, C, "sheet shifted"},
    {S::shift_check, Ev::sheet_settled, Guard::slide_too_long, S::abort, Reason::slide_out_of_range,
     "slide longer than max_slide_mm"},
    {S::shift_check, Ev::sheet_settled, Guard::slide_again, S::shift_slide, C, "corner short of its target: slide on"},
    {S::shift_check, Ev::sheet_settled, Guard::none, S::abort, Reason::shift_short,
     "corner short of its target after max_slides"},

    // The pinching hand shifted: it lets go and lifts, then the fixing hand comes down to fixate.
    {S::grasp_open, Ev::hand_pin_posed, Guard::none, S::grasp_lift, C, "shifting hand open"},
    {S::grasp_lift, Ev::arm_pin_reached, Guard::none, S::grasp_park, C, "shifting hand lifted"},
    // Parked (in joint space) as at the start, from where the grasp's way was made: from over the
    // sheet its first motion was refused (unreachable).
    {S::grasp_park, Ev::arm_pin_reached, Guard::none, S::grasp_fix_approach, C, "shifting hand parked"},
    {S::grasp_fix_approach, Ev::arm_fix_reached, Guard::fixing_armed, S::grasp_fix_contact, C,
     "fixing tool above the fixation point"},
    {S::grasp_fix_contact, Ev::arm_fix_contact, Guard::none, S::grasp_fixate, C, "fixing hand touches the sheet"},
    {S::grasp_fix_contact, Ev::arm_fix_missed, Guard::none, S::abort, Reason::no_contact,
     "no contact at the descent's depth"},
    // clang-format on

    {S::grasp_fixate, Ev::hand_fix_settled, Guard::none, S::grasp_shape, C, "fixing hand fixates"},
    // Shaped before the arm moves: arm_motion takes the tool frame's offset from the hand as it
    // is when a motion starts, and the grasp's orientations are the shaped pad's.
    {S::grasp_shape, Ev::hand_pin_posed, Guard::none, S::grasp_above, C, "pinching hand shaped"},
    {S::grasp_above, Ev::arm_pin_reached, Guard::none, S::grasp_reach, C,
     "pinching tool above the corner"},
    {S::grasp_reach, Ev::arm_pin_reached, Guard::none, S::grasp_pinch, C,
     "pinching tool at the corner"},
    {S::grasp_pinch, Ev::pinched, Guard::none, S::bend, C, "corner pinched"},

    {S::bend_crease, Ev::crease_acked, Guard::none, S::follow_via, C, "model has the crease"},
    {S::follow_via, Ev::arm_pin_reached, Guard::more_via, S::follow_via, C, "via point reached"},
    {S::follow_via, Ev::arm_pin_reached, Guard::last_via, S::fixate_layer, C,
     "last via point reached"},

    {S::layer_lay, Ev::arm_pin_reached, Guard::none, S::refixate, C,
     "bent layer laid on the stack"},

    // The fixing hand lies under the bent layer: out from under it first, the pinch holding it.
    {S::refix_slide_out, Ev::arm_fix_reached, Guard::none, S::refix_open, C,
     "fixing hand out from under the layer"},
    {S::refix_open, Ev::hand_fix_posed, Guard::none, S::refix_lift, C, "fixing hand open"},
    {S::refix_lift, Ev::arm_fix_reached, Guard::none, S::refix_approach, C, "fixing hand lifted"},
    {S::refix_approach, Ev::arm_fix_reached, Guard::fixing_armed, S::refix_contact, C,
     "fixing tool above both layers"},
    {S::refix_contact, Ev::arm_fix_contact, Guard::none, S::refix_press, C,
     "fixing hand touches both layers"},
    {S::refix_contact, Ev::arm_fix_missed, Guard::none, S::abort, Reason::no_contact,
     "no contact at the descent's depth"},
    {S::refix_press, Ev::hand_fix_settled, Guard::none, S::swipe, C, "both layers fixated"},

    // Both layers fixated: the pinch lets go of the edge (the thumb opens) and its pads leave it.
    {S::swipe_release, Ev::hand_pin_posed, Guard::none, S::swipe_withdraw, C, "pinch released"},
    {S::swipe_withdraw, Ev::arm_pin_reached, Guard::none, S::swipe_open, C,
     "pinching hand off the edge"},
    {S::swipe_open, Ev::hand_pin_posed, Guard::none, S::swipe_lift, C, "pinching hand open"},
    {S::swipe_lift, Ev::arm_pin_reached, Guard::none, S::swipe_approach, C, "pinching hand lifted"},
    {S::swipe_approach, Ev::arm_pin_reached, Guard::pinching_armed, S::swipe_contact, C,
     "pinching tool above the swipe"},
    {S::swipe_contact, Ev::arm_pin_contact, Guard::none, S::swipe_press, C,
     "pinching hand touches the fold"},
    {S::swipe_contact, Ev::arm_pin_missed, Guard::none, S::abort, Reason::no_contact,
     "no contact at the descent's depth"},
    {S::swipe_press, Ev::hand_pin_settled, Guard::none, S::swipe_slide, C, "swipe force settled"},
    {S::swipe_slide, Ev::arm_pin_reached, Guard::none, S::harden, C, "swiped"},

    {S::harden_open, Ev::hand_pin_posed, Guard::none, S::harden_lift, C, "pinching hand open"},
    {S::harden_lift, Ev::arm_pin_reached, Guard::none, S::harden_approach, C,
     "pinching hand lifted"},
    {S::harden_approach, Ev::arm_pin_reached, Guard::pinching_armed, S::harden_contact, C,
     "pinching tool above the crease"},
    {S::harden_contact, Ev::arm_pin_contact, Guard::none, S::harden_press, C,
     "two fingers on the crease"},
    {S::harden_contact, Ev::arm_pin_missed, Guard::none, S::abort, Reason::no_contact,
     "no contact at the descent's depth"},
    {S::harden_press, Ev::hand_pin_settled, Guard::none, S::harden_slide, C,
     "hardening force settled"},
    {S::harden_slide, Ev::arm_pin_reached, Guard::none, S::finish, C, "crease hardened"},

    {S::finish_memorize, Ev::memorized, Guard::none, S::finish_open, C, "model memorized the fold"},
    {S::finish_open, Ev::hands_posed, Guard::none, S::finish_lift, C, "hands open"},
    {S::finish_lift, Ev::arms_reached, Guard::none, S::finish_park, C, "hands lifted"},
    {S::finish_park, Ev::arms_reached, Guard::none, S::done, C, "arms parked"},

    {S::done, Ev::start, Guard::ready, S::fold, Reason::started, "start"},

    {S::abort, Ev::timeout, Guard::none, S::aborted, Reason::timeout, "abort timed out"},
    {S::abort_stop, Ev::stopped, Guard::none, S::abort_open, C, "force stopped, arms still"},
    {S::abort_stop, Ev::timeout, Guard::none, S::abort_open, Reason::timeout, "stop timed out"},
    {S::abort_open, Ev::hands_posed, Guard::none, S::abort_lift, C, "hands open"},
    {S::abort_open, Ev::timeout, Guard::none, S::abort_lift, Reason::timeout, "open timed out"},
    {S::abort_lift, Ev::arms_done, Guard::none, S::abort_reopen, C, "lift ended"},
    {S::abort_lift, Ev::timeout, Guard::none, S::abort_reopen, Reason::timeout, "lift timed out"},
    // Off the sheet, open again: a hand whose opening pressed a fingertip over its force limit
    // on the sheet retreated and refused goals while it read over it (force_controller's latch);
    // lifted, it takes this one, which clears the latch, and arm_motion takes the park after it.
    {S::abort_reopen, Ev::hands_posed, Guard::none, S::abort_park, C, "hands open, lifted"},
    {S::abort_reopen, Ev::timeout, Guard::none, S::abort_park, Reason::timeout, "reopen timed out"},
    {S::abort_park, Ev::arms_done, Guard::none, S::aborted, C, "park ended"},
    {S::abort_park, Ev::timeout, Guard::none, S::aborted, Reason::timeout, "park timed out"},

    {S::aborted, Ev::start, Guard::ready, S::fold, Reason::started, "start"},
};
constexpr int kRowCount = static_cast<int>(sizeof(kRows) / sizeof(kRows[0]));

constexpr bool rows_in_order() {
  for (int i = 1; i < kRowCount; ++i)
    if (kRows[i].from < kRows[i - 1].from) return false;
  return true;
}
static_assert(rows_in_order(), "kRows are grouped by state in S's order");

constexpr const char* kReasonNames[] = {
    "none",         "started",        "condition",          "timeout",
    "device_fault", "vision_lost",    "force_limit",        "unreachable",
    "goal_refused", "motion_aborted", "slide_out_of_range", "no_sheet",
    "command_lost", "operator_abort", "no_contact",         "pinch_lost",
    "fold_lost",    "shift_short",
};
static_assert(sizeof(kReasonNames) / sizeof(kReasonNames[0]) == static_cast<std::size_t>(Reason::count));

}  // namespace

const char* reason_name(Reason r) noexcept {
  const auto i = static_cast<std::size_t>(r);
  return i < static_cast<std::size_t>(Reason::count) ? kReasonNames[i] : "?";
}

const StateInfo& state_info(S s) noexcept { return kStatesTable[static_cast<std::size_t>(s)]; }

int depth(S s) noexcept {
  int d = 0;
  while (s != S::root) {
    s = state_info(s).parent;
    ++d;
  }
  return d;
}

bool is_within(S s, S ancestor) noexcept {
  for (;;) {
    if (s == ancestor) return true;
    if (s == S::root) return false;
    s = state_info(s).parent;
  }
}

bool layer_laid(S s) noexcept {
  return is_within(s, S::fixate_layer) || is_within(s, S::refixate) || is_within(s, S::swipe) ||
         is_within(s, S::harden);
}

RowSpan all_rows() noexcept { return {kRows, kRows + kRowCount}; }

RowSpan rows_of(S s) noexcept {
  const Row* b = kRows;
  while (b != kRows + kRowCount && b->from < s) ++b;
  const Row* e = b;
  while (e != kRows + kRowCount && e->from == s) ++e;
  return {b, e};
}

S state_by_path(std::string_view path) noexcept {
  for (int i = 1; i < kStateCount; ++i) {
    char buf[96];
    write_path(static_cast<S>(i), -1, buf, sizeof buf);
    if (path == buf) return static_cast<S>(i);
  }
  return S::count;
}

void write_path(S s, int via, char* out, std::size_t n) noexcept {
  if (n == 0) return;
  S chain[8];
  int k = 0;
  for (S x = s; x != S::root && k < 8; x = state_info(x).parent) chain[k++] = x;
  std::size_t at = 0;
  auto put = [&](const char* t) {
    while (*t != '\0' && at + 1 < n) out[at++] = *t++;
  };
  for (int i = k - 1; i >= 0; --i) {
    put(state_info(chain[i]).name);
    if (i > 0) put("/");
  }
  if (s == S::follow_via && via >= 0) {
    char digits[8];
    int d = 0;
    unsigned v = static_cast<unsigned>(via);
    do {
      digits[d++] = static_cast<char>('0' + v % 10);
      v /= 10;
    } while (v != 0 && d < 7);
    put("[");
    while (d > 0 && at + 1 < n) out[at++] = digits[--d];
    put("]");
  }
  out[at] = '\0';
}

}  // namespace crease::fold
