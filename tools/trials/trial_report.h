// crease-trials' HTML report: one self-contained page (inline CSS and SVG, no scripts, no
// external files): the summary line's figures, one row per trial, and per trial a plot over
// the time since the sequence's start of its states (bands along the top, each path in the
// band's tooltip), each hand's largest fingertip force (N, left axis) and the sheet's largest
// edge stretch (%, right axis, the torn threshold marked). Non-RT.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "tools/trials/trial_run.h"

namespace crease::trials {

// Each line of a plot keeps at most this many points: a longer series is cut into windows,
// each drawn as its largest value (a force spike stays visible). NaN values are gaps.
inline constexpr std::size_t kPlotMaxPoints = 2000;

// The page for RESULTS (in the order given); FOLD and FAULTS as for summary_line.
[[nodiscard]] std::string trials_html(const std::vector<TrialResult>& results, const std::string& fold, bool faults);

}  // namespace crease::trials
