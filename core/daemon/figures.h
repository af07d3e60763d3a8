// The figures plugins report (every latest port of type crease::Figure, core/port_types/figure.h),
// read by creased for its progress lines and summary. The daemon knows nothing of what is
// measured: each plugin names its figure. Non-RT.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/port_registry.h"
#include "core/port_types/figure.h"
#include "core/report/timing_report.h"

namespace crease::daemon {

struct FigureReading {
  std::string port;
  Figure figure;             // the newest value
  double window_mean = 0;    // mean of the samples since the previous take()
  std::uint64_t window_count = 0;
};

class FigureWatch {
 public:
  explicit FigureWatch(const PortRegistry& ports) : ports_(ports) {}
  // The figures now (ports of type Figure, in name order), each with its window since the
  // previous take().
  std::vector<FigureReading> take();

 private:
  const PortRegistry& ports_;
  std::vector<FigureReading> last_;
};

// Every figure now (by port name), as the report and `creasectl stats` show it.
[[nodiscard]] std::vector<report::FigureSummary> figure_summaries(const PortRegistry& ports);
// The same of figures taken earlier (FigureWatch::take): the report creased writes at its end
// takes them before the host drives every output, these too, to its safe value.
[[nodiscard]] std::vector<report::FigureSummary> figure_summaries(const std::vector<FigureReading>& figures);

// "; LABEL: X UNIT (this second), Y UNIT (mean so far)" for each figure with samples.
[[nodiscard]] std::string progress_text(const std::vector<FigureReading>& figures);
// "  LABEL: mean X UNIT over N SAMPLE, last L UNIT, worst W UNIT" lines.
[[nodiscard]] std::string summary_text(const std::vector<FigureReading>& figures);

}  // namespace crease::daemon
