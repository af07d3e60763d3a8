// Test plugin for the write phase: a driver-like probe. update publishes what it "sensed" this
// cycle (`sensed`, count = the cycle index); write takes the command some other plugin built
// from it (`command`, latest TestValue) and pushes how many cycles old that sensing was
// (`lags` queue: value = lag in cycles, count = cycle index). With a write phase the lag is 0.
#include <cstdint>

#include "core/plugin.h"
#include "plugins/test_plugins/test_ports.h"

namespace {
using crease::test_plugins::TestValue;

class PhaseProbe final : public crease::Plugin {
 public:
  void configure(const crease::Params&, crease::PortBinder& ports) override {
    sensed_ = ports.latest_output<TestValue>("sensed", TestValue{-1.0, 0, 0});
    command_ = ports.latest_input<TestValue>("command");
    lags_ = ports.queue_output<TestValue>("lags", 4096);
  }
  crease::Status update(const crease::Cycle& cycle) override {
    sensed_.write(TestValue{static_cast<double>(cycle.index), cycle.index, 1}, cycle.time_ns);
    return crease::Status::ok;
  }
  crease::Status write(const crease::Cycle& cycle) {
    if (!command_.poll().has_data()) return crease::Status::degraded;
    const double lag = static_cast<double>(cycle.index) - static_cast<double>(command_.value().count);
    (void)lags_.try_push(TestValue{lag, cycle.index, 1});
    return crease::Status::ok;
  }

 private:
  crease::LatestOutput<TestValue> sensed_;
  crease::LatestInput<TestValue> command_;
  crease::QueueOutput<TestValue> lags_;
};
}  // namespace

CREASE_PLUGIN(PhaseProbe, "test_phase_probe", "1.0.0")
