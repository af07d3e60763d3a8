// crease-trials' output: one row per trial, the summary line, the JSON summary. Non-RT.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/trials/trial_run.h"

namespace crease::trials {

// One line: the trial, its seed, how the sequence ended and where, the scores, the verdict.
[[nodiscard]] std::string row(const TrialResult& r);

// The last line: `trials: fold=half n=20 success=k faults=0 fold_line_mm_p95=… angle_deg_p95=…
// corners_mm_p95=… retained_deg_min=… mean_s=…`. A trial without a figure (no fold: no fold
// line) counts as the worst value (inf) in a p95 and the minimum; mean_s over every trial.
[[nodiscard]] std::string summary_line(const std::vector<TrialResult>& results, const std::string& fold, bool faults);

// The nearest-rank p-th percentile (0..100) of VALUES, NaN counted as +inf; NaN when empty.
[[nodiscard]] double percentile(std::vector<double> values, double p);

// Everything: the run's options, every trial's result, the summary line.
[[nodiscard]] nlohmann::json summary_json(const std::vector<TrialResult>& results, const std::string& fold,
                                          std::uint64_t seed, bool faults);

}  // namespace crease::trials
