// Port payload `Figure`: a running figure a plugin reports for the daemon's progress lines and
// summary (a tracking error, a success rate). The daemon shows every latest port of this type
// and knows nothing of what is measured: the plugin names it.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/port_types/payload_layout.h"

namespace crease {

struct Figure {
  static constexpr char kPortType[] = "crease.Figure";
  static constexpr std::uint32_t kPortVersion = 1;

  char label[64] = {};   // what is measured, e.g. "tracking error of sheet_state vs sheet_truth"
  char unit[8] = {};     // e.g. "mm"
  char sample[16] = {};  // what one sample is, e.g. "model frames"
  std::uint64_t count = 0;  // samples so far
  double sum = 0;           // of every sample (a reader's window mean: change of sum / change of count)
  double last = 0;          // the newest sample
  double max = 0;           // the worst sample

  // A figure with no samples yet, named: each text is cut to fit its field.
  [[nodiscard]] static Figure named(const char* what, const char* unit_text, const char* sample_text) {
    Figure f{};
    std::strncpy(f.label, what, sizeof f.label - 1);
    std::strncpy(f.unit, unit_text, sizeof f.unit - 1);
    std::strncpy(f.sample, sample_text, sizeof f.sample - 1);
    return f;
  }

  // A share of events, in %: EVENTS so far, HITS of them (late frames, dropped views); the newest
  // sample is 100 when HITS grew since the last call (PREV_HITS), else 0. RT.
  void set_share(std::uint64_t events, std::uint64_t hits, std::uint64_t prev_hits) noexcept {
    count = events;
    sum = 100.0 * static_cast<double>(hits);
    last = hits != prev_hits ? 100.0 : 0.0;
    max = hits > 0 ? 100.0 : 0.0;
  }

  [[nodiscard]] bool all_finite() const { return std::isfinite(sum) && std::isfinite(last) && std::isfinite(max); }
  [[nodiscard]] double mean() const { return count ? sum / static_cast<double>(count) : 0.0; }
};
CREASE_PORT_PAYLOAD_LAYOUT(Figure, 120, 8);

}  // namespace crease
