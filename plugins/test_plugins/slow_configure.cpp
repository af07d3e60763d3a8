// Test plugin whose configure takes `configure_ms` (default 0, at most 60000) of wall time,
// sleeping: a start-up that takes as long as the tests need (creased's start-up stop test).
// Output: `out` (latest TestValue, its update count; safe value: value -1).
#include <chrono>
#include <cstdint>
#include <thread>

#include "core/plugin.h"
#include "plugins/test_plugins/test_ports.h"

namespace {
using crease::test_plugins::TestValue;

class SlowConfigure final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    const auto ms = p.get_in_range<std::int64_t>("configure_ms", 0, 0, 60000);
    out_ = ports.latest_output<TestValue>("out", TestValue{-1.0, 0, 0});
    std::this_thread::sleep_for(std::chrono::milliseconds(ms));  // configure is non-RT
  }
  crease::Status update(const crease::Cycle& cycle) override {
    ++n_;
    out_.write(TestValue{static_cast<double>(n_), n_, 1}, cycle.time_ns);
    return crease::Status::ok;
  }

 private:
  std::uint64_t n_ = 0;
  crease::LatestOutput<TestValue> out_;
};
}  // namespace

CREASE_PLUGIN(SlowConfigure, "test_slow_configure", "1.0.0")
