// Plugin `doubler`: the README's example. out = k * in, every cycle; k is a parameter and a
// tunable (creasectl param set <instance> k 3).
#include "core/plugin.h"
#include "gain.h"

class Doubler final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {  // non-RT
    k_ = p.get_in_range<double>("k", 2.0, 0.0, 10.0);   // errors name file, line, key
    ports.tunable("k", &k_, 0.0, 10.0);
    in_ = ports.latest_input<Gain>("in");
    out_ = ports.latest_output<Gain>("out", Gain{0.0});  // the safe value
  }
  crease::Status update(const crease::Cycle& c) override {  // RT: no alloc, lock, syscall, throw
    const auto info = in_.poll();                 // the input keeps the newest value
    if (!info.has_data()) return crease::Status::degraded;   // never written yet
    out_.write(Gain{k_ * in_.value().value}, c.time_ns);   // held across cycles with nothing new
    return crease::Status::ok;
  }

 private:
  double k_ = 2.0;
  crease::LatestInput<Gain> in_;
  crease::LatestOutput<Gain> out_;
};
CREASE_PLUGIN(Doubler, "doubler", "1.0.0")
