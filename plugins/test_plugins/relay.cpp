// Test plugin: a controller stand-in that copies its latest input `in` to its output `out`
// every cycle (once there is an input). Safe value: value -1.
#include "core/plugin.h"
#include "plugins/test_plugins/test_ports.h"

namespace {
using crease::test_plugins::TestValue;

class Relay final : public crease::Plugin {
 public:
  void configure(const crease::Params&, crease::PortBinder& ports) override {
    in_ = ports.latest_input<TestValue>("in");
    out_ = ports.latest_output<TestValue>("out", TestValue{-1.0, 0, 0});
  }
  crease::Status update(const crease::Cycle& cycle) override {
    if (!in_.poll().has_data()) return crease::Status::degraded;
    out_.write(in_.value(), cycle.time_ns);
    return crease::Status::ok;
  }

 private:
  crease::LatestInput<TestValue> in_;
  crease::LatestOutput<TestValue> out_;
};
}  // namespace

CREASE_PLUGIN(Relay, "test_relay", "1.0.0")
