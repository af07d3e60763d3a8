// The contact controller's parameters (README.md), validated at configure time: every error
// names the file, line and key (crease::ConfigError), e.g.
//   sim.yaml:88:20: plugins[7].params.weights.FFJ9: unknown joint 'FFJ9' (did you mean 'FFJ3'?)
// Non-RT.
#pragma once

#include "core/params.h"
#include "plugins/contact_controller/contact_detector.h"

namespace crease::contact {

[[nodiscard]] ContactConfig read_contact_config(const Params& p);

// The P selector/weights by joint name (drivers/README.md §3 names, no side prefix): a map
// name -> weight in [0, 100]. Absent: the default selection (WRJ1 and every finger's J3 and J2,
// weight 1). Shared reading of any per-joint map: unknown names are refused.
[[nodiscard]] std::array<double, kJoints> read_joint_map(const Params& p, const char* key, double lo, double hi,
                                                         const std::array<double, kJoints>& fallback);

}  // namespace crease::contact
