// Reads and validates the force controller's parameters at configure time (crease::ConfigError
// naming file, line and key for each problem: unknown joints in alpha, alpha on a joint that
// is not a finger's flexion, a distal alpha above its proximal one, negative gains, thresholds
// out of range). Loads the robot's files (param `robot`) for the joint limits and the side's
// tactile calibration. Non-RT.
#pragma once

#include "core/params.h"
#include "plugins/force_controller/force_config.h"

namespace crease::force {

[[nodiscard]] ForceConfig read_force_config(const Params& p);

}  // namespace crease::force
