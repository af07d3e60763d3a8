// Port payload `Figure`: a running figure a plugin reports for the daemon's progress lines and
// summary (a tracking error, a success rate). The daemon shows every latest port of this type
// and knows nothing of what is measured: the plugin names it.
#pragma once

#include <cmath>
#include <cstdint>

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

  [[nodiscard]] bool all_finite() const { return std::isfinite(sum) && std::isfinite(last) && std::isfinite(max); }
  [[nodiscard]] double mean() const { return count ? sum / static_cast<double>(count) : 0.0; }
};
CREASE_PORT_PAYLOAD_LAYOUT(Figure, 120, 8);

}  // namespace crease
