// The machine's events, guards and fault checks: every success condition is a fact of the
// sensing about the goal the state sent (its id echoed by the controller), never elapsed time.
#include <algorithm>
#include <cmath>

#include "plugins/fold_sequence/machine.h"
#include "plugins/fold_sequence/sheet_geometry.h"

namespace crease::fold {
namespace {

bool fresh(std::int64_t stamp_ns, std::int64_t now_ns, double max_age_s) noexcept {
  return static_cast<double>(now_ns - stamp_ns) * 1e-9 <= max_age_s;
}

bool moving(const ArmMotionStatus* a) noexcept {
  return a != nullptr && (a->state == ArmMotionStatus::checking || a->state == ArmMotionStatus::running ||
                          a->state == ArmMotionStatus::stopping);
}

// A refusal or abort that the same goal sent again cannot mend: the goal itself, or a drive in
// fault (its driver commanded the safe state; a drive back from a fault is a new start). A stale
// arm_state (arm_stale, arm_not_ready) is one of a loaded machine's moments.
bool for_good(std::uint8_t reason) noexcept {
  switch (static_cast<ArmMotionReason>(reason)) {
    case ArmMotionReason::arm_fault:
    case ArmMotionReason::non_finite:
    case ArmMotionReason::bad_orientation:
    case ArmMotionReason::unknown_tool:
    case ArmMotionReason::bad_points:
    case ArmMotionReason::bad_limits:
    case ArmMotionReason::outside_workspace:
    case ArmMotionReason::no_sheet:
    case ArmMotionReason::unreachable:
    case ArmMotionReason::joint_speed: return true;
    default: return false;
  }
}

// The distance from P to the segment A-B (world mm).
double segment_distance(const double p[3], const double a[3], const double b[3]) noexcept {
  double ab[3], ap[3];
  for (int c = 0; c < 3; ++c) {
    ab[c] = b[c] - a[c];
    ap[c] = p[c] - a[c];
  }
  const double ll = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
  const double t =
      ll > 0 ? std::clamp((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / ll, 0.0, 1.0) : 0.0;
  double d2 = 0;
  for (int c = 0; c < 3; ++c) d2 += (ap[c] - t * ab[c]) * (ap[c] - t * ab[c]);
  return std::sqrt(d2);
}

}  // namespace

RetreatEnd retreat_end(const ArmMotionStatus* a, std::uint32_t id) noexcept {
  if (id == 0) return RetreatEnd::reached;  // nothing sent: an arm that never moved
  if (a == nullptr) return RetreatEnd::pending;
  if (a->last_refused_id == id) return for_good(a->last_refusal) ? RetreatEnd::gave_up : RetreatEnd::retry;
  if (a->goal_id != id || moving(a) || a->state == ArmMotionStatus::idle) return RetreatEnd::pending;
  if (a->state == ArmMotionStatus::reached || a->state == ArmMotionStatus::stopped_on_contact) return RetreatEnd::reached;
  return for_good(a->reason) ? RetreatEnd::gave_up : RetreatEnd::retry;
}

bool Machine::holds(Ev ev, S owner, const Sensing& in) const noexcept {
  auto reached = [&](int s) {
    const ArmMotionStatus* a = in.arm[s];
    return m_.arm_id[s] == 0 ||
           (a != nullptr && a->goal_id == m_.arm_id[s] && a->state == ArmMotionStatus::reached);
  };
  auto contact_stop = [&](int s) {
    const ArmMotionStatus* a = in.arm[s];
    return a != nullptr && m_.arm_id[s] != 0 && a->goal_id == m_.arm_id[s] &&
           a->state == ArmMotionStatus::stopped_on_contact;
  };
  auto settled = [&](int s) {
    const HandControlStatus* h = in.hand[s];
    return h != nullptr && m_.hand_id[s] != 0 && h->goal_id == m_.hand_id[s] && h->mode == HandMode::force &&
           h->settled != 0;
  };
  // The side's posture goal of this state ramped to its end (the targets no longer move).
  auto ramp_ended = [&](int s) {
    const HandControlStatus* h = in.hand[s];
    return h != nullptr && m_.hand_id[s] != 0 && h->goal_id == m_.hand_id[s] && h->mode == HandMode::posture &&
           h->max_step_rad <= 1e-6f;
  };
  auto posed = [&](int s) {
    const HandControlStatus* h = in.hand[s];
    if (m_.hand_id[s] == 0) return true;
    if (h == nullptr) return false;
    // Refused (in the fold a fault first), or the controller's own retreat: nothing more to wait for.
    if (h->goals_refused > m_.hand_refused0[s] || h->mode == HandMode::retreat) return true;
    return ramp_ended(s);
  };
  switch (ev) {
    case Ev::start: return m_.start_pending != 0;
    case Ev::timeout: return timed_out(owner);
    case Ev::fault: return detected_ != Reason::none;
    case Ev::arm_fix_reached: return m_.arm_id[kFixing] != 0 && reached(kFixing);
    case Ev::arm_shift_reached:
      return m_.arm_id[spec_.shift_role] != 0 && reached(spec_.shift_role);
    case Ev::arm_shift_contact:
      return contact_stop(spec_.shift_role);
    case Ev::arm_shift_missed:
      return m_.arm_id[spec_.shift_role] != 0 && reached(spec_.shift_role);
    case Ev::hand_shift_settled:
      return settled(spec_.shift_role);
    case Ev::arm_pin_reached: return m_.arm_id[kPinching] != 0 && reached(kPinching);
    case Ev::arms_reached: return reached(kFixing) && reached(kPinching);
    case Ev::arm_fix_contact: return contact_stop(kFixing);
    case Ev::arm_pin_contact: return contact_stop(kPinching);
    // The descent's goal reached (its depth lies below the surface): nothing was touched.
    case Ev::arm_fix_missed: return m_.arm_id[kFixing] != 0 && reached(kFixing);
    case Ev::arm_pin_missed: return m_.arm_id[kPinching] != 0 && reached(kPinching);
    case Ev::hand_fix_settled: return settled(kFixing);
    case Ev::hand_pin_settled: return settled(kPinching);
    case Ev::hand_fix_posed: return m_.hand_id[kFixing] != 0 && posed(kFixing);
    case Ev::hand_pin_posed: return m_.hand_id[kPinching] != 0 && posed(kPinching);
    case Ev::hands_posed: return posed(kFixing) && posed(kPinching);
    case Ev::pinched: {
      // The closing ended and every pinching pad measures the squeeze. Not contact_state's
      // fingers: a finger still following its ramped targets reads as a contact there, with
      // the corner nowhere between the pads.
      if (!ramp_ended(kPinching)) return false;
      const HandControlStatus* h = in.hand[kPinching];
      for (int f = 0; f < HandControlStatus::kFingers; ++f)
        if ((spec_.pinch_fingers & (1u << f)) != 0 && !(h->force_n[f] >= spec_.pinch_force_n)) return false;
      return true;
    }
    case Ev::crease_acked: return in.sheet != nullptr && in.sheet->crease_count > m_.crease_count0;
    case Ev::sheet_settled:
      return in.sheet != nullptr &&
             in.sheet->timestamp_ns >=
                 m_.leaf_since_ns + static_cast<std::int64_t>(spec_.shift_settle_s * 1e9);
    case Ev::memorized: return in.sheet != nullptr && in.sheet->step >= m_.sheet_step0 + 2;
    case Ev::stopped:
      for (int s = 0; s < 2; ++s) {
        const HandControlStatus* h = in.hand[s];
        const bool hand_ok = h == nullptr || m_.hand_id[s] == 0 || h->mode == HandMode::retreat ||
                             (h->goal_id == m_.hand_id[s] && h->mode == HandMode::hold) ||
                             h->goals_refused > m_.hand_refused0[s];
        if (!hand_ok || moving(in.arm[s])) return false;
      }
      return true;
    case Ev::arms_done:
      for (int s = 0; s < 2; ++s) {
        const RetreatEnd e = retreat_end(in.arm[s], m_.arm_id[s]);
        if ((e != RetreatEnd::reached && e != RetreatEnd::gave_up) || joints_park_due(s, in) ||
            (m_.leaf == S::abort_park && m_.park_joints[s] == Memory::kParkLifting))
          return false;
      }
      return true;
    case Ev::always: return true;
  }
  return false;
}

double Machine::slide_length(const Sensing& in, double d_sheet[2],
                             double d_world[2]) const noexcept {
  SheetFrame f;
  double corner[3];
  if (in.sheet == nullptr || !sheet_frame(*in.sheet, f) || !node_at(*in.sheet, spec_.corner_mm[0], spec_.corner_mm[1], corner))
    return std::nan("");
  // The corner's way to its target on the table plane, expressed along the sheet's axes.
  const double d[3] = {spec_.corner_target_mm[0] - corner[0], spec_.corner_target_mm[1] - corner[1], 0.0};
  d_sheet[0] = d[0] * f.x[0] + d[1] * f.x[1] + d[2] * f.x[2];
  d_sheet[1] = d[0] * f.y[0] + d[1] * f.y[1] + d[2] * f.y[2];
  if (d_world != nullptr) {
    d_world[0] = d[0];
    d_world[1] = d[1];
  }
  return std::hypot(d[0], d[1]);
}

bool Machine::passes(Guard g, const Sensing& in) const noexcept {
  double d[2];
  switch (g) {
    case Guard::none: return true;
    case Guard::ready: {
      const SheetState* sh = in.sheet;
      if (sh == nullptr || !fresh(sh->timestamp_ns, in.now_ns, spec_.sheet_max_age_s) ||
          sh->observations < spec_.min_observations)
        return false;
      for (int s = 0; s < 2; ++s) {
        const HandControlStatus* h = in.hand[s];
        const ArmMotionStatus* a = in.arm[s];
        const ContactState* c = in.contact[s];
        if (h == nullptr || a == nullptr || c == nullptr || !fresh(h->timestamp_ns, in.now_ns, spec_.status_max_age_s) ||
            !fresh(a->timestamp_ns, in.now_ns, spec_.status_max_age_s) ||
            !fresh(c->timestamp_ns, in.now_ns, spec_.status_max_age_s) || c->healthy == 0 || h->commanding == 0)
          return false;
      }
      return true;
    }
    case Guard::slide_needed:
    case Guard::slide_again: {
      const double l = slide_length(in, d);
      return l > spec_.shift_tolerance_mm && l <= spec_.max_slide_mm &&
             (g == Guard::slide_needed || m_.slides < spec_.max_slides);
    }
    case Guard::slide_too_long: return slide_length(in, d) > spec_.max_slide_mm;
    case Guard::shifted_by_fixing:
    case Guard::shifted_by_pinching:  // the corner within the tolerance, and that hand shifted
      return spec_.shift_role == (g == Guard::shifted_by_fixing ? kFixing : kPinching) &&
             slide_length(in, d) <= spec_.shift_tolerance_mm;
    case Guard::fixing_armed:
    case Guard::pinching_armed:
    case Guard::shift_armed: {
      const int role = g == Guard::fixing_armed     ? kFixing
                       : g == Guard::pinching_armed ? kPinching
                                                    : spec_.shift_role;
      const ContactState* c = in.contact[role];
      return c != nullptr && c->armed != 0 && c->healthy != 0;
    }
    case Guard::more_via: return m_.via + 1 < spec_.via_count;
    case Guard::last_via: return m_.via + 1 >= spec_.via_count;
  }
  return false;
}

namespace {

// The fault's source, per side (0 right, 1 left): string literals for the status's `why`.
struct Side {
  const char* hand_stale;
  const char* arm_stale;
  const char* contact_stale;
  const char* contact_unhealthy;
  const char* inhibit[6];  // by HandInhibit
  const char* goal_refused;
  const char* arm_refused;
  const char* arm_fault;
  const char* arm_state_stale;
  const char* arm_aborted;
};
constexpr Side kSide[2] = {
    {"hand_r status stale",
     "arm_r status stale",
     "contact_r status stale",
     "contact_r unhealthy",
     {"hand_r inhibit", "hand_r hand_state fault", "hand_r hand_state stale",
      "hand_r tactile fault", "hand_r tactile stale", "hand_r force limit"},
     "hand_r goal refused",
     "arm_r goal refused",
     "arm_r arm fault",
     "arm_r arm_state stale",
     "arm_r motion aborted"},
    {"hand_l status stale",
     "arm_l status stale",
     "contact_l status stale",
     "contact_l unhealthy",
     {"hand_l inhibit", "hand_l hand_state fault", "hand_l hand_state stale",
      "hand_l tactile fault", "hand_l tactile stale", "hand_l force limit"},
     "hand_l goal refused",
     "arm_l goal refused",
     "arm_l arm fault",
     "arm_l arm_state stale",
     "arm_l motion aborted"},
};

}  // namespace

Reason Machine::fault(const Sensing& in) noexcept {
  detail_ = nullptr;
  const std::int64_t now = in.now_ns;
  // The sheet as vision and the model see it: stale or unobserved for longer than the bound.
  const SheetState* sh = in.sheet;
  const bool seen = sh != nullptr && fresh(sh->timestamp_ns, now, spec_.sheet_max_age_s) &&
                    sh->observations >= spec_.min_observations;
  if (seen) {
    m_.vision_bad_since_ns = 0;
  } else if (m_.vision_bad_since_ns == 0) {
    m_.vision_bad_since_ns = now;
  } else if (static_cast<double>(now - m_.vision_bad_since_ns) * 1e-9 > spec_.vision_lost_max_s) {
    detail_ = sh == nullptr || !fresh(sh->timestamp_ns, now, spec_.sheet_max_age_s)
                  ? "sheet_state stale"
                  : "sheet unobserved";
    return Reason::vision_lost;
  }
  const auto found = [this](const char* what, Reason r) noexcept {
    detail_ = what;
    return r;
  };
  for (int s = 0; s < 2; ++s) {
    const HandControlStatus* h = in.hand[s];
    const ArmMotionStatus* a = in.arm[s];
    const ContactState* c = in.contact[s];
    const Side& n = kSide[side_of_role(spec_, s)];  // s is a role; the names are the side's
    // Controllers that do not answer, or answer that their inputs are bad: a device fault.
    if (h == nullptr || !fresh(h->timestamp_ns, now, spec_.status_max_age_s))
      return found(n.hand_stale, Reason::device_fault);
    if (a == nullptr || !fresh(a->timestamp_ns, now, spec_.status_max_age_s))
      return found(n.arm_stale, Reason::device_fault);
    if (c == nullptr || !fresh(c->timestamp_ns, now, spec_.status_max_age_s))
      return found(n.contact_stale, Reason::device_fault);
    if (c->healthy == 0) return found(n.contact_unhealthy, Reason::device_fault);
    // The force controller stopped adding force since the fold began (its inhibits counter
    // rose): over its force limit, or its inputs went bad.
    if (h->inhibits > m_.inhibits0[s] && h->inhibit != HandInhibit::none) {
      const auto i = static_cast<std::size_t>(h->inhibit);
      detail_ = n.inhibit[i < std::size(n.inhibit) ? i : 0];
      return h->inhibit == HandInhibit::force_limit ? Reason::force_limit : Reason::device_fault;
    }
    if (m_.hand_id[s] != 0 && h->goals_refused > m_.hand_refused0[s])
      return found(n.goal_refused, Reason::goal_refused);
    const std::uint32_t id = m_.arm_id[s];
    if (id == 0) continue;
    if (a->last_refused_id == id || (a->goal_id == id && (a->state == ArmMotionStatus::unreachable ||
                                                          a->state == ArmMotionStatus::refused))) {
      const auto why = static_cast<ArmMotionReason>(end_reason(*a, id));
      return found(n.arm_refused,
                   why == ArmMotionReason::unreachable || why == ArmMotionReason::joint_speed
                       ? Reason::unreachable
                       : Reason::goal_refused);
    }
    if (a->goal_id == id && a->state == ArmMotionStatus::aborted) {
      const auto why = static_cast<ArmMotionReason>(a->reason);
      if (why == ArmMotionReason::arm_fault) return found(n.arm_fault, Reason::device_fault);
      if (why == ArmMotionReason::arm_stale) return found(n.arm_state_stale, Reason::device_fault);
      return found(n.arm_aborted, Reason::motion_aborted);
    }
  }
  if (flap_open(in)) return found("the laid layer's printed face seen", Reason::fold_lost);
  // Off the way on every model state for pinch_lost_s: the tracker alone can put it there for a
  // moment (its error over a trial's frames reaches 30-60 mm at its worst).
  if (!seen) return Reason::none;  // a state without observations tells nothing either way
  bool judged = true;
  const Reason off = grasp_off(*sh, judged);
  if (judged && off == Reason::none) {  // unjudged (within the state's lag): the time runs on
    m_.pinch_off_since_ns = 0;
  } else if (judged && m_.pinch_off_since_ns == 0) {
    m_.pinch_off_since_ns = now;
  }
  if (m_.pinch_off_since_ns != 0 &&
      static_cast<double>(now - m_.pinch_off_since_ns) * 1e-9 >= spec_.pinch_lost_s)
    return found(off == Reason::fold_lost ? "tracked grasp point off the laid layer"
                                          : "tracked grasp point off the pinch",
                 off);
  return Reason::none;
}

Reason Machine::grasp_off(const SheetState& sh, bool& judged) const noexcept {
  // The pinching tool's way in this state and the one before it: from the point before the one
  // it left, through the point it left (the grasp, or a via point), to the one it goes to; in the
  // sheet frame as the tracked sheet has it now. The way before too because the model's flap,
  // the hand hiding it from the cameras, lags the pinch by up to a segment (a trial: 47 mm behind
  // 0.3 s into follow_via[3], the pinch holding). Judged on a model state made at least
  // kModelLagNs after the state began.
  constexpr std::int64_t kModelLagNs = 150'000'000;
  const bool lay = m_.leaf == S::layer_lay;
  // Once the pinch let go (swipe from its withdraw on, harden), the laid layer is held by the
  // fixing hand alone and may spring back: the grasp point then lies far from where it was laid
  // (lay_mm's u, v on the stack, in the frame the lay's goal went out in).
  // From the swipe's stroke on, the stroke itself moves the laid layer (trials, 2026-12-06: a
  // fold that held, 172 deg, its grasp point pushed over 100 mm towards the crease): where it was
  // laid says nothing then, and with the printed-face check on (flap_seen_points) that alone
  // judges the layer.
  const bool stroked = m_.leaf == S::swipe_slide || is_within(m_.leaf, S::harden);
  const bool laid = ((is_within(m_.leaf, S::swipe) && m_.leaf != S::swipe_release) ||
                     is_within(m_.leaf, S::harden)) &&
                    !(stroked && spec_.flap_seen_points > 0);
  judged = true;
  const bool checked =
      (m_.leaf == S::follow_via || lay) ? spec_.pinch_lost_mm > 0 : laid && spec_.fold_lost_mm > 0;
  if (!checked || spec_.via_count == 0) return Reason::none;
  if (sh.timestamp_ns < m_.leaf_since_ns + kModelLagNs) {
    judged = false;
    return Reason::none;
  }
  if (laid) {
    SheetFrame live;
    double g[3], at[3];
    if (!sheet_frame(sh, live) || !node_at(sh, spec_.grasp_at_mm[0], spec_.grasp_at_mm[1], g))
      return Reason::none;
    // Where the lay put the edge, in the lay's frame: the one held from the bend, else the tracked.
    const double on_stack[3] = {spec_.lay_mm[0], spec_.lay_mm[1], 0.0};
    sheet_to_world(m_.frame_held != 0 ? m_.held_frame : live, on_stack, at);
    const double d = std::hypot(g[0] - at[0], g[1] - at[1], g[2] - at[2]);
    return d > spec_.fold_lost_mm ? Reason::fold_lost : Reason::none;
  }
  const int k =
      lay ? spec_.via_count : std::min<int>(m_.via, spec_.via_count - 1);  // the point it goes to
  const auto point = [&](int i) {
    return i < 0 ? spec_.grasp_at_mm : i < spec_.via_count ? spec_.via_mm[i] : spec_.lay_mm;
  };
  SheetFrame f;
  double g[3], w[3][3];
  if (!sheet_frame(sh, f) || !node_at(sh, spec_.grasp_at_mm[0], spec_.grasp_at_mm[1], g))
    return Reason::none;
  const int first = std::max(-1, k - 2);
  for (int i = first; i <= k; ++i) sheet_to_world(f, point(i), w[i - first]);
  double d = segment_distance(g, w[k - 1 - first], w[k - first]);
  if (k - first == 2) d = std::min(d, segment_distance(g, w[0], w[1]));
  return d > spec_.pinch_lost_mm ? Reason::pinch_lost : Reason::none;
}

bool Machine::grasp_target(const Sensing& in, double world_mm[3],
                           double sheet_mm[2]) const noexcept {
  const S leaf = m_.leaf;
  // The pinch holds the layer from the bend's first via point until the swipe releases it (the
  // refixation moves the fixing hand only).
  const bool holding =
      leaf == S::follow_via || is_within(leaf, S::fixate_layer) || is_within(leaf, S::refixate);
  const ArmMotionStatus* a = in.arm[kPinching];
  if (!holding || a == nullptr || a->tool_measured == 0 || a->tool != spec_.grasp_tool ||
      !a->all_finite())
    return false;
  for (int c = 0; c < 3; ++c) world_mm[c] = a->tool_mm[c];
  sheet_mm[0] = spec_.grasp_at_mm[0];
  sheet_mm[1] = spec_.grasp_at_mm[1];
  return true;
}

bool Machine::press_target(const Sensing& in, double world_mm[3],
                           double sheet_mm[2]) const noexcept {
  const S leaf = m_.leaf;
  const bool pressing = leaf == S::refix_press || is_within(leaf, S::swipe) ||
                        is_within(leaf, S::harden) || leaf == S::finish_memorize;
  const ArmMotionStatus* a = in.arm[kFixing];
  if (!pressing || m_.press_held == 0 || a == nullptr || a->tool_measured == 0 ||
      a->tool != spec_.refixate.tool || !a->all_finite())
    return false;
  for (int c = 0; c < 3; ++c) world_mm[c] = a->tool_mm[c];
  sheet_mm[0] = m_.press_uv[0];
  sheet_mm[1] = m_.press_uv[1];
  return true;
}

bool Machine::flap_open(const Sensing& in) noexcept {
  // Laid, the layer shows the cameras its unprinted back (a sprung-open layer showed 112-170
  // key-points where the laid one left 5-20 in a trial, seed 23); the markers' key-points say so
  // within a frame or two, where the model, held by the grasp and press targets, may keep the
  // layer laid for seconds.
  constexpr double kBeyondMm = 15.0;  // a model cell past the line: not the crease's own row
  const Keypoints* k = in.keypoints;
  if (spec_.flap_seen_points == 0 || !layer_laid(m_.leaf) || k == nullptr ||
      !fresh(k->timestamp_ns, in.now_ns, spec_.sheet_max_age_s)) {
    m_.flap_seen_since_ns = 0;
    return false;
  }
  std::uint32_t n = 0;
  const std::uint32_t count = std::min(k->count, Keypoints::kCapacity);
  for (std::uint32_t i = 0; i < count; ++i) {
    const Keypoint& p = k->points[i];
    if (p.face == 0 && beyond_line(spec_.fold_line_mm[0], spec_.fold_line_mm[1], spec_.grasp_at_mm,
                                   p.sheet_mm[0], p.sheet_mm[1]) > kBeyondMm)
      ++n;
  }
  if (n < spec_.flap_seen_points) {
    m_.flap_seen_since_ns = 0;
    return false;
  }
  if (m_.flap_seen_since_ns == 0) m_.flap_seen_since_ns = in.now_ns;
  return static_cast<double>(in.now_ns - m_.flap_seen_since_ns) * 1e-9 >= spec_.flap_seen_s;
}

}  // namespace crease::fold
