// A trial's result as JSON and back (result.json, trials.json): every figure, the timeline, the
// series and the sheet the score was taken from; non-finite figures as null.
#pragma once

#include <nlohmann/json.hpp>

#include "tools/trials/trial_run.h"

namespace crease::trials {

[[nodiscard]] nlohmann::json to_json(const TrialResult& r);
[[nodiscard]] TrialResult from_json(const nlohmann::json& j);

}  // namespace crease::trials
