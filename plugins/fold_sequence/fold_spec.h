// A fold as data: what one sequence file (config/folds/*.yaml) says about a fold of seed 000
// Fig. 7, steps (a)-(h): where each hand touches the sheet, the via points of the bend, the
// forces, the motions' limits, the sensing bounds, the timeouts and the fold line.
//
// Points of the sheet are in arm_motion's sheet frame (ArmGoal::sheet): origin at node (0, 0),
// x along u, y along v, z = u x v into the paper; a sheet lying printed face up has z pointing
// into the table, so a height h mm above the sheet is z = -h. Files give (u, v) in mm and heights
// in mm above the sheet (`[u, v, h]`); FoldSpec stores sheet-frame points (z = -h).
// Parking poses are in the world frame (mm, z up). Forces N, durations s, speeds mm/s, rad/s.
// Loaded at configure (non-RT); the machine reads it at run time without changing it.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace crease::fold {

inline constexpr int kMaxVia = 16;
inline constexpr int kMaxGraspPath = 7;  // with at_mm, one arm goal's points (ArmGoal::kMaxPoints)
inline constexpr int kHandJoints = 20;
inline constexpr int kStates = 64;  // at least the machine's state count (states.h checks it)

// An arm motion's limits (ArmGoal's fields of the same names).
struct MotionLimits {
  float speed_mm_s = 50;
  float accel_mm_s2 = 300;
  float angular_speed_rad_s = 0.5f;
  float angular_accel_rad_s2 = 3;
  float stop_accel_mm_s2 = 2000;
};

// One hand landing on the sheet with C_contact and pressing with C_force: above `at` by
// approach_height_mm, then down towards contact_depth_mm below the surface, stopped by a contact
// onset of a finger in `fingers`, then force_n per finger in `fingers` (the thumb never).
struct ContactStep {
  std::uint8_t tool = 0;     // robot::ToolFrame (0..4 pads ff mf rf lf th, 5..9 backs)
  std::uint8_t fingers = 1;  // bit f: finger f (ff mf rf lf th)
  double at_mm[2] = {0, 0};  // (u, v) on the sheet
  double approach_height_mm = 30;
  double contact_depth_mm = 5;
  double force_n = 1;
  double orientation[4] = {0, 0, 0, 1};  // the tool frame in the sheet frame, quaternion x y z w
};

struct FoldSpec {
  std::string name;     // e.g. "half"
  std::string file;     // where it was read from
  double fold_line_mm[2][2] = {};  // the crease the fold intends: (u0, v0), (u1, v1), sheet mm

  // Sensing bounds.
  // The pinch lost (bend and lay): the tracked sheet's grasp point (the node nearest grasp.at_mm's
  // u, v) further than this (mm) from the pinching tool's way in the state and the one before
  // (Machine::grasp_off). 0: not checked.
  double pinch_lost_mm = 0;
  double pinch_lost_s = 0;  // ... on every observed model state for this long (0: the first)
  // The laid layer lost (swipe, harden: the pinch let go): the grasp point further than this (mm)
  // from where the layer was laid, for pinch_lost_s. 0: not checked.
  double fold_lost_mm = 0;
  // The laid layer sprung open, seen (fixate_layer, refixate, swipe, harden): laid, the layer
  // shows the cameras its unprinted back; at least this many marker key-points of its printed
  // face (keypoints: face 0, (u, v) beyond the fold line by more than 15 mm) in every frame for
  // flap_seen_s: it lies open. 0: not checked.
  std::uint32_t flap_seen_points = 0;
  double flap_seen_s = 0.3;
  double vision_lost_max_s = 0.5;   // sheet_state stale, or fewer than min_observations, this long: abort
  std::uint32_t min_observations = 1;
  double sheet_max_age_s = 0.2;     // a sheet_state older than this is not the current sheet
  double status_max_age_s = 0.05;   // a controller's status older than this: device fault

  // Every state's timeout (s), by state id; default `timeout_s`, per state `timeouts_s`.
  std::array<double, kStates> timeout_s{};

  MotionLimits approach, contact, slide, fold, retreat;

  // Which side pinches (0 right, 1 left; the other fixes): the machine's roles (machine.h).
  int pinching_side = 1;

  // Hand postures (20 joints, drivers/README.md's order, rad) and their ramp.
  float open_rad[kHandJoints] = {};
  float prepinch_rad[kHandJoints] = {};  // shaped for the reach to the corner; open_rad when absent
  float pinch_rad[kHandJoints] = {};
  // (f) the pinch opens at this stiffness (N m/rad per joint; has_release_stiffness false: as
  // the hand's controller holds it): a soft thumb opening between the layers presses the stack
  // with what its spring gives, not with a stiff joint's push past the paper.
  float release_stiffness[kHandJoints] = {};
  bool has_release_stiffness = false;
  double posture_ramp_s = 0.3;
  double release_ramp_s =
      0.3;  // the pinch's opening over the laid layer (swipe/release); ramp_s if absent
  double force_ramp_s = 0.1;       // a force goal's target ramp

  // (a) shift: the fixing hand presses at shift.at, then slides the sheet so that `corner_mm`
  // (u, v) moves to `corner_target_mm` (world x, y): the slide's vector from the tracked pose.
  ContactStep shift;
  double corner_mm[2] = {0, 0};
  double corner_target_mm[2] = {0, 0};
  double shift_tolerance_mm = 3;   // no slide when the corner is this close already
  double max_slide_mm = 150;       // a longer slide aborts (reason slide_out_of_range)
  // After each slide the tracked sheet, settle_s after the arm arrived, says whether the corner is
  // within the tolerance; short of it (the finger slipped over the sheet) the rest is slid from
  // where the finger is, up to max_slides slides in all (then abort: shift_short).
  int max_slides = 4;
  // The hand that shifts (the file's shift.hand): the fixing one (kFixing, the default: it stays
  // and fixates) or the pinching one (kPinching: seed 000's rubber hand, where the fixing hand's
  // cover grips paper less than the table does and slides over it; it then lets go and lifts,
  // and the fixing hand comes down on `fixate`).
  int shift_role = 0;
  double shift_lift_mm =
      100;  // the pinching hand's lift after it shifted, before it takes its pinch's posture
  double shift_settle_s = 0.3;
  double slide_height_mm = 0;      // the tool frame's height above the sheet while sliding

  // (b) grasp: the fixing hand fixates with fixate_force_n; the pinching one takes prepinch_rad while its
  // tool moves (through grasp_above_via) to above_mm, then moves through grasp_path_mm (e.g. round the sheet's edge and up
  // under its overhang) to at_mm, then closes to pinch_rad until the force controller measures
  // at least pinch_force_n on every finger of pinch_fingers with the posture's ramp ended.
  double fixate_force_n = 2;
  // Where the fixing hand fixates (tool, fingers, at_mm, orientation, approach and contact
  // depth): the shift's contact when the fixing hand shifted; grasp.fixate when the pinching one
  // did.
  ContactStep fixate;
  std::uint8_t grasp_tool = 4;
  std::uint8_t pinch_fingers = 0x11;  // th + ff
  double pinch_force_n = 0.2;
  int grasp_above_via_count = 0;   // points the pinching tool passes on its way to above_mm,
  double grasp_above_via_mm[kMaxGraspPath][3] = {};         // each with its own orientation
  double grasp_above_via_orientation[kMaxGraspPath][4] = {};  // (a turn the straight path cannot make)
  // Per above_via point, `frame: world`: its at_mm (x, y, z up) and orientation are the world's,
  // the same whatever the sheet's yaw (the sequence puts it into the sheet frame it sends in);
  // else (`sheet`, the default) a sheet point like the others, turning with the sheet.
  bool grasp_above_via_world[kMaxGraspPath] = {};
  double grasp_above_mm[3] = {};   // sheet frame
  int grasp_path_count = 0;
  double grasp_path_mm[kMaxGraspPath][3] = {};
  double grasp_at_mm[3] = {};
  double grasp_orientation[4] = {0, 0, 0, 1};

  // (c) bend: the pinching tool through via points (sheet frame of the sheet at each one's start).
  int via_count = 0;
  double via_mm[kMaxVia][3] = {};
  double via_orientation[kMaxVia][4] = {};
  // The via points' orientations turn with the sheet's heading only within this range (deg)
  // about the heading they were drawn for (the sheet's u axis at yaw_reference_deg in the world):
  // the points follow the sheet, the pad's turn stays within the arm's reach. Unset: all the way.
  bool bend_yaw_limited = false;
  double bend_yaw_reference_deg = 0;
  double bend_yaw_range_deg[2] = {-180, 180};

  // (d) the pinch lays the bent layer on the stack and holds it there: the pinching tool to
  // lay_mm (sheet frame), turned as the last via point.
  double lay_mm[3] = {};
  // (e) the fixing hand, under the bent layer since (b), slides out from under it to
  // refixate_out_mm (u, v; at slide_height_mm) pressing with refixate_out_force_n, opens,
  // lifts, and lands on both layers as `refixate` says.
  double refixate_out_mm[2] = {0, 0};
  double refixate_out_force_n = 0.5;
  ContactStep refixate;
  double release_lift_mm = 30;     // a hand lifts this far after it opened (e, f, g)
  // The abort's park out of reach on a line goes in joint space; first the hand is lifted this
  // far straight up (0: not): the joints' own path from a wrist turned by the bend can swing
  // the hand through the table (trials: world fingertip forces of 1-2 kN in abort/park).
  double park_lift_mm = 150;

  // (f) the pinch opens to prepinch_rad (the thumb off the edge), its tool moves to
  // swipe_withdraw_mm (sheet frame, the pads off the edge), the hand opens and lifts; the coarse
  // swipe: the pinching hand lands at swipe.at and slides to swipe_to_mm (u, v).
  double swipe_withdraw_mm[3] = {};
  ContactStep swipe;
  double swipe_to_mm[2] = {0, 0};

  // (g) hardening: two fingers along the model's crease line, inset from its ends, offset
  // across it (towards +v of the line's normal), landing as `harden` says (its at_mm unused).
  ContactStep harden;
  double harden_inset_mm = 10;
  double harden_offset_mm = 0;

  // (h) and the abort's retreat: lift, then park (world frame mm, quaternion x y z w).
  double park_mm[2][3] = {};       // [right, left]
  double park_orientation[2][4] = {{0, 0, 0, 1}, {0, 0, 0, 1}};
};

// Reads a sequence file. Throws ConfigError "FILE:LINE:COLUMN: fold.KEY: reason" for a file that
// cannot be read or parsed, a missing, mistyped, out-of-range or unknown key.
[[nodiscard]] FoldSpec load_fold_file(const std::string& path);

// The tool frame and finger names files use: "ff_pad", "th_back", "palm_front", "flange"; "ff"...
[[nodiscard]] int tool_index(const std::string& name);    // -1 when unknown
[[nodiscard]] int finger_index(const std::string& name);  // -1 when unknown

}  // namespace crease::fold
