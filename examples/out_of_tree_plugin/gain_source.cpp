// Plugin `gain_source`: writes the constant `value` (parameter, default 1) on `out` once, at its
// first cycle. Its readers keep that value on every later cycle (a latest port holds it).
#include "core/plugin.h"
#include "gain.h"

class GainSource final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    value_ = p.get_in_range<double>("value", 1.0, -1e6, 1e6);
    out_ = ports.latest_output<Gain>("out", Gain{0.0});
  }
  crease::Status update(const crease::Cycle& c) override {
    if (!written_) out_.write(Gain{value_}, c.time_ns);
    written_ = true;
    return crease::Status::ok;
  }

 private:
  double value_ = 1.0;
  bool written_ = false;
  crease::LatestOutput<Gain> out_;
};
CREASE_PLUGIN(GainSource, "gain_source", "1.0.0")
