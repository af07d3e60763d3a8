#include "core/daemon/figures.h"

#include <cstdio>
#include <cstring>

namespace crease::daemon {

std::vector<FigureReading> FigureWatch::take() {
  std::vector<FigureReading> now;
  for (const PortInfo& p : ports_.list()) {
    if (p.kind != PortKind::latest || p.type_name != Figure::kPortType || p.size != sizeof(Figure)) continue;
    const rt::LatestChannel* ch = ports_.find_latest(p.name);
    if (ch == nullptr) continue;
    FigureReading r;
    r.port = p.name;
    if (!ch->read(&r.figure, 0).has_data()) continue;
    r.figure.label[sizeof(r.figure.label) - 1] = '\0';  // a plugin's text, terminated here whatever it wrote
    r.figure.unit[sizeof(r.figure.unit) - 1] = '\0';
    r.figure.sample[sizeof(r.figure.sample) - 1] = '\0';
    double sum0 = 0;
    std::uint64_t count0 = 0;
    for (const FigureReading& l : last_) {
      if (l.port == r.port && l.figure.count <= r.figure.count) {
        sum0 = l.figure.sum;
        count0 = l.figure.count;
      }
    }
    r.window_count = r.figure.count - count0;
    r.window_mean = r.window_count ? (r.figure.sum - sum0) / static_cast<double>(r.window_count) : 0.0;
    now.push_back(r);
  }
  last_ = now;
  return now;
}

std::vector<report::FigureSummary> figure_summaries(const std::vector<FigureReading>& figures) {
  std::vector<report::FigureSummary> out;
  for (const FigureReading& r : figures) {
    out.push_back({r.port, r.figure.label, r.figure.unit, r.figure.sample, r.figure.count, r.figure.mean(),
                   r.figure.last, r.figure.max});
  }
  return out;
}

std::vector<report::FigureSummary> figure_summaries(const PortRegistry& ports) {
  return figure_summaries(FigureWatch(ports).take());
}

std::string progress_text(const std::vector<FigureReading>& figures) {
  std::string out;
  for (const FigureReading& r : figures) {
    if (r.figure.count == 0) continue;
    char buf[256];
    if (r.window_count == 0) {  // no sample this second (its source paused or gone): no figure for it
      std::snprintf(buf, sizeof(buf), "; %s: no %s (this second), %.2f %s (mean so far)", r.figure.label,
                    r.figure.sample, r.figure.mean(), r.figure.unit);
    } else {
      std::snprintf(buf, sizeof(buf), "; %s: %.2f %s (this second), %.2f %s (mean so far)", r.figure.label,
                    r.window_mean, r.figure.unit, r.figure.mean(), r.figure.unit);
    }
    out += buf;
  }
  return out;
}

std::string summary_text(const std::vector<FigureReading>& figures) {
  std::string out;
  for (const FigureReading& r : figures) {
    if (r.figure.count == 0) continue;
    char buf[320];
    std::snprintf(buf, sizeof(buf), "  %s: mean %.2f %s over %llu %s, last %.2f %s, worst %.2f %s\n", r.figure.label,
                  r.figure.mean(), r.figure.unit, static_cast<unsigned long long>(r.figure.count), r.figure.sample,
                  r.figure.last, r.figure.unit, r.figure.max, r.figure.unit);
    out += buf;
  }
  return out;
}

}  // namespace crease::daemon
