// Test plugin whose configure takes `configure_ms` (default 0, at most 60000) of wall time,
// sleeping: a start-up that takes as long as the tests need (creased's start-up stop tests).
// `started_file` / `finished_file` (default: none): created when configure begins sleeping /
// after it slept, so a test can tell whether a stop cut its configure short.
// Output: `out` (latest TestValue, its update count; safe value: value -1).
#include <chrono>
#include <cstdint>
#include <fstream>
#include <string>
#include <thread>

#include "core/plugin.h"
#include "plugins/test_plugins/test_ports.h"

namespace {
using crease::test_plugins::TestValue;

void touch(const std::string& path) {
  if (!path.empty()) std::ofstream(path) << "configure\n";
}

class SlowConfigure final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    const auto ms = p.get_in_range<std::int64_t>("configure_ms", 0, 0, 60000);
    const auto started = p.get<std::string>("started_file", "");
    const auto finished = p.get<std::string>("finished_file", "");
    out_ = ports.latest_output<TestValue>("out", TestValue{-1.0, 0, 0});
    touch(started);
    std::this_thread::sleep_for(std::chrono::milliseconds(ms));  // configure is non-RT
    touch(finished);
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
