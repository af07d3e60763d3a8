// arm_motion's parameters (the plugin's `params:` map), validated at configure time: every error
// is a crease::ConfigError "FILE:LINE:COLUMN: plugins[i].params.KEY: reason".
//
//   side: right                      # required: right | left
//   robot: robot/crease_robot.yaml   # the robot's parameter file (and through it the URDF),
//                                    #   relative to the configuration's folder
//   max_speed_mm_s: 250              # the most a goal may ask, along the tool frame's path
//   max_accel_mm_s2: 2000
//   max_angular_speed_rad_s: 1.5
//   max_angular_accel_rad_s2: 12
//   max_stop_accel_mm_s2: 5000       # the hardest stop deceleration a goal may ask
//   workspace_min_mm: [-700, -800, -10]   # the box every point must lie in (world, mm)
//   workspace_max_mm: [700, 600, 900]
//   arm_state_max_age_ms: 5          # older: stale (a running motion aborts and holds)
//   hand_state_max_age_ms: 20        # a hand tool frame's goal needs one this fresh
//   contact_state_max_age_ms: 5      # a stop condition needs one this fresh
//   sheet_state_max_age_ms: 200      # a sheet-frame goal needs one this fresh
//   check_samples_per_cycle: 1       # path samples solved ahead per cycle before a motion runs
//   check_step_mm: 5                 # their spacing (and check_step_rad in rotation)
//   check_step_rad: 0.05
//   joint_speed_fraction: 0.9        # of each joint's URDF velocity limit a path may need
//   rest_posture_deg: [...]          # the IK's null-space preference (7 angles, S1..W2); default
//                                    #   per side: the palm flat 150 mm above the table, fingers
//                                    #   forward (right: -36 -19.5 -15.1 54.9 54 71.2 148.3)
//   track_iterations: 4              # IK iterations per cycle at most
// Non-RT.
#pragma once

#include <string>

#include "core/params.h"
#include "plugins/arm_motion/arm_motion.h"
#include "plugins/robot_model/robot_model.h"

namespace crease::arm_motion {

struct ArmMotionConfig {
  robot::Side side = robot::Side::right;
  std::string robot_path;
  MotionParams motion;
};

// Everything but the rest posture's limits (which need the model: check_rest_posture).
[[nodiscard]] ArmMotionConfig parse_arm_motion_params(const Params& p);

// Throws naming rest_posture_deg when a joint of it lies outside that joint's URDF limits.
void check_rest_posture(const Params& p, const ArmMotionConfig& c, const robot::RobotModel& m);

}  // namespace crease::arm_motion
