// Port payloads of one arm's Cartesian motion (plugins/arm_motion):
//   `arm_goal` (queue, in):            a motion to run: a tool frame through up to kMaxPoints
//                                      poses (via points, then the target), limits, a stop condition;
//   `arm_motion_status` (latest, out): what the motion is doing, how far it got, why goals were
//                                      refused or aborted (counted per reason).
// Millimetres, radians, seconds; quaternions (x, y, z, w), unit length within 1e-3. Tool frames
// are robot_model's ToolFrame (plugins/robot_model/robot_layout.h): 0..4 pads ff mf rf lf th,
// 5..9 the finger backs, 10 the palm's front, 11 the arm's flange.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/port_types/payload_layout.h"

namespace crease {

struct ArmGoal {
  static constexpr char kPortType[] = "crease.ArmGoal";
  static constexpr std::uint32_t kPortVersion = 3;  // 2: interpolation; 3: kind retreat
  static constexpr int kMaxPoints = 8;

  enum Kind : std::uint8_t {
    move = 0,  // run the motion below (refused as busy while another one is active)
    stop = 1,  // decelerate whatever runs at its stop deceleration and hold (nothing else read)
    // A move back out the way the tool went in (the sender vouches for the path: e.g. the
    // grasp's reach in reverse): taken, and kept running, while the hand's controller retreats,
    // as a lift is; any other move is refused then (hand_retreat).
    retreat = 2,
  };
  enum Frame : std::uint8_t {
    world = 0,  // points in the world frame
    sheet = 1,  // points in the sheet frame as sheet_state gives it at the motion's start:
                // origin node (0, 0), x towards node (W-1, 0) (u), z = u x v, y = z x x
    measured = 2,  // relative to the tool frame's measured pose at the motion's start (the
                   // forward kinematics of arm_state's angles): each point's position is an
                   // offset along the world's axes, its orientation a rotation in the world
                   // frame applied to the measured orientation (identity: keep it). A lift
                   // from where the arm is, wherever a stopped motion left it.
  };
  enum Interpolation : std::uint8_t {
    cartesian = 0,  // the tool frame along straight lines through the points (the IK each cycle)
    joints = 1,     // one point, no stop condition: its pose solved once (the IK seeded from the
                    // arm's first measured posture, where it started parked), then every joint
                    // on one smooth profile to it: a retreat to the parking pose from a pose
                    // whose straight line there the arm cannot follow (a wrist turned by a bend)
  };
  enum StopOn : std::uint8_t {
    stop_none = 0,
    contact_onset = 1,  // contact_state reports a new onset (its `onsets` counter rose since the
                        // motion started) with a finger of stop_fingers in contact, or a finger
                        // of stop_fingers joins a contact held since the motion started
  };

  std::int64_t timestamp_ns = 0;
  std::uint32_t id = 0;          // the sender's; echoed by arm_motion_status
  std::uint8_t kind = move;
  std::uint8_t tool = 0;         // robot::ToolFrame
  std::uint8_t frame = world;
  std::uint8_t point_count = 0;  // 1..kMaxPoints: via points, the last is the target
  std::uint8_t stop_on = stop_none;
  std::uint8_t stop_fingers = 0x1f;  // bit f: finger f (ff mf rf lf th)
  std::uint8_t interpolation = cartesian;
  // Limits of the tool frame's motion along its path (each > 0, at most arm_motion's params).
  float speed_mm_s = 0;
  float accel_mm_s2 = 0;
  float angular_speed_rad_s = 0;
  float angular_accel_rad_s2 = 0;
  float stop_accel_mm_s2 = 0;        // deceleration when the stop condition fires (>= accel_mm_s2)
  double position_mm[kMaxPoints][3] = {};
  double orientation[kMaxPoints][4] = {};  // quaternion x y z w of the tool frame

  [[nodiscard]] bool all_finite() const {
    // Goals are refused with a counted reason, never faulted: any bytes may be queued.
    return true;
  }
};

CREASE_PORT_PAYLOAD_LAYOUT(ArmGoal, 488, 8);

// Why a goal was refused (nothing moved) or a motion aborted (stopped and held): the index
// into ArmMotionStatus::reasons.
enum class ArmMotionReason : std::uint8_t {
  none = 0,
  non_finite,          // a NaN or infinity in a point or a limit
  bad_orientation,     // a quaternion not of unit length (1e-3)
  unknown_tool,        // tool not a ToolFrame
  bad_points,          // point_count 0 or above kMaxPoints, unknown frame, kind or stop_on
  bad_limits,          // a speed or acceleration <= 0, or above the parameters' limits
  outside_workspace,   // a point outside the workspace box
  no_sheet,            // frame == sheet without a sheet_state, or one older than its bound
  no_hand_state,       // a hand tool frame without a fresh hand_state
  no_contact_state,    // a stop condition without a fresh, armed, healthy contact_state
  arm_not_ready,       // arm_state missing, stale, faulted or not operation enabled
  unreachable,         // no IK solution within the joint limits at some point of the path
  joint_speed,         // the path needs a joint faster than its velocity limit
  arm_fault,           // while running: arm_state faulted or left operation enabled
  arm_stale,           // while running: arm_state older than its bound
  contact_stale,       // while a stop condition is armed: contact_state stale or unhealthy
  tracking_lost,       // while running: the IK lost the path (a bug or a singularity)
  busy,                // a move goal while another motion is checked, runs or stops (stop it first)
  stopped,             // a stop goal
  hand_retreat,        // the hand's controller retreats or stopped adding force (hand_control_status:
                       // mode retreat, an inhibit, or the status stale): a running motion decelerates
                       // and aborts, a goal is refused
  count
};
inline constexpr int kArmMotionReasons = static_cast<int>(ArmMotionReason::count);

struct ArmMotionStatus {
  static constexpr char kPortType[] = "crease.ArmMotionStatus";
  static constexpr std::uint32_t kPortVersion = 2;  // 2: tool_mm, tool_measured
  static constexpr int kReasons = 20;
  enum State : std::uint8_t {
    idle = 0,            // holding the last command, no goal yet
    checking = 1,        // a goal arrived: its path is being solved ahead (nothing moves)
    running = 2,
    stopping = 3,        // the stop condition (or a stop goal, an abort) fired: decelerating
    reached = 4,         // the target reached; its command held
    stopped_on_contact = 5,
    unreachable = 6,     // refused at arrival: reason unreachable or joint_speed
    refused = 7,         // refused at arrival for any other reason
    aborted = 8,         // stopped and held: reason arm_fault, arm_stale, contact_stale, ...
  };

  std::int64_t timestamp_ns = 0;
  std::uint32_t goal_id = 0;   // of the goal this state is about
  std::uint32_t last_refused_id = 0;  // the last goal refused (also while another one runs)
  std::uint8_t state = idle;
  std::uint8_t reason = 0;     // ArmMotionReason of that goal's refusal or abort (0: none)
  std::uint8_t tool = 0;
  std::uint8_t segment = 0;    // the path segment running (0: towards the first point)
  std::uint8_t last_refusal = 0;  // ArmMotionReason of the last refused goal
  std::uint8_t tool_measured = 0;  // 1: tool_mm holds this cycle's measured tool position
  float progress = 0;          // 0..1 along the whole path (by segments' parameter)
  float speed_mm_s = 0;        // the commanded tool frame's speed now
  float distance_to_go_mm = 0; // to the target along the path
  float ik_error_mm = 0;       // the IK's residual at this cycle's command
  // Where the tool frame (`tool`: the last goal's) is, world mm: forward kinematics of the arm's
  // joint readings this cycle (the hand's fingers as at that goal). Valid when tool_measured.
  float tool_mm[3] = {};
  std::uint32_t goals_accepted = 0;
  std::uint32_t goals_refused = 0;
  std::uint32_t motions_aborted = 0;
  std::uint32_t reasons[kReasons] = {};  // per ArmMotionReason: how often it refused or aborted

  [[nodiscard]] bool all_finite() const {
    return std::isfinite(progress) && std::isfinite(speed_mm_s) &&
           std::isfinite(distance_to_go_mm) && std::isfinite(ik_error_mm) &&
           std::isfinite(tool_mm[0]) && std::isfinite(tool_mm[1]) && std::isfinite(tool_mm[2]);
  }
};
static_assert(kArmMotionReasons <= ArmMotionStatus::kReasons, "one counter per reason");

CREASE_PORT_PAYLOAD_LAYOUT(ArmMotionStatus, 144, 8);

}  // namespace crease
