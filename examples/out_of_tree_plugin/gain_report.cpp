// Plugin `gain_report`: shows a Gain port in creased's progress lines and summary, as a Figure
// (core/port_types/figure.h): one sample per cycle with a value.
#include <cstring>

#include "core/plugin.h"
#include "core/port_types/figure.h"
#include "gain.h"

class GainReport final : public crease::Plugin {
 public:
  void configure(const crease::Params&, crease::PortBinder& ports) override {
    std::strncpy(figure_.label, "example gain", sizeof(figure_.label) - 1);
    std::strncpy(figure_.sample, "cycles", sizeof(figure_.sample) - 1);
    in_ = ports.latest_input<Gain>("in");
    out_ = ports.latest_output<crease::Figure>("figure", figure_);
  }
  crease::Status update(const crease::Cycle& c) override {
    if (!in_.poll().has_data()) return crease::Status::degraded;
    const double v = in_.value().value;
    figure_.count += 1;
    figure_.sum += v;
    figure_.last = v;
    figure_.max = figure_.count == 1 || v > figure_.max ? v : figure_.max;
    out_.write(figure_, c.time_ns);
    return crease::Status::ok;
  }

 private:
  crease::Figure figure_{};
  crease::LatestInput<Gain> in_;
  crease::LatestOutput<crease::Figure> out_;
};
CREASE_PLUGIN(GainReport, "gain_report", "1.0.0")
