// The folding sequences plugins report (every latest port of type crease::SequenceStatus,
// core/port_types/sequence_status.h), for `creasectl status`: each one's state path, time in
// state, phase and last transition. The daemon knows nothing of the states. Non-RT.
#pragma once

#include <nlohmann/json.hpp>

#include "core/port_registry.h"

namespace crease::daemon {

// One object per sequence_status port with a value, in port name order:
// {"port", "fold", "path", "phase", "time_in_state_s", "why", "transitions", "aborts", "step_mode"}.
[[nodiscard]] nlohmann::json sequences_view(const PortRegistry& ports);

}  // namespace crease::daemon
