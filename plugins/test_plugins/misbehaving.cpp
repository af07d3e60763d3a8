// Test plugins that misbehave on purpose after `after` updates (default 10), each built as its
// own library (MISBEHAVIOUR): 1 throws, 2 writes NaN, 3 returns fault, 4 allocates every update,
// 5 burns `busy_us` of wall time every update (overrun tests; preempted, it burns less CPU) and
// then sleeps `sleep_us` (a plugin that blocks), 6 does nothing at all (overhead bench).
// Output: `out` (latest TestValue, safe value: value -1).
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>

#include "core/plugin.h"
#include "plugins/test_plugins/test_ports.h"
#include "rt/clock.h"

namespace {
using crease::test_plugins::TestValue;

class Misbehaving final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    after_ = p.get<std::int64_t>("after", 10);
    busy_ns_ = p.get_in_range<std::int64_t>("busy_us", 0, 0, 10'000'000) * 1000;
    sleep_ns_ = p.get_in_range<std::int64_t>("sleep_us", 0, 0, 10'000'000) * 1000;
    out_ = ports.latest_output<TestValue>("out", TestValue{-1.0, 0, 0});
  }
  crease::Status update(const crease::Cycle& cycle) override {
    ++n_;
    const bool misbehave = static_cast<std::int64_t>(n_) > after_;
    TestValue v{static_cast<double>(n_), n_, 1};
#if MISBEHAVIOUR == 1
    if (misbehave) throw std::runtime_error("thrown on purpose");
#elif MISBEHAVIOUR == 2
    if (misbehave) v.value = std::numeric_limits<double>::quiet_NaN();
#elif MISBEHAVIOUR == 3
    if (misbehave) return crease::Status::fault;
#elif MISBEHAVIOUR == 4
    if (misbehave) sink_ = std::make_unique<int>(static_cast<int>(n_));
#elif MISBEHAVIOUR == 5
    const std::int64_t until = crease::rt::now_ns() + busy_ns_;
    while (crease::rt::now_ns() < until) {
    }
    if (sleep_ns_ > 0) crease::rt::sleep_until_ns(crease::rt::now_ns() + sleep_ns_);
#elif MISBEHAVIOUR == 6
    return crease::Status::ok;
#endif
    (void)misbehave;
    out_.write(v, cycle.time_ns);
    return crease::Status::ok;
  }

 private:
  std::int64_t after_ = 10;
  std::int64_t busy_ns_ = 0;
  std::int64_t sleep_ns_ = 0;
  std::uint64_t n_ = 0;
  std::unique_ptr<int> sink_;
  crease::LatestOutput<TestValue> out_;
};
}  // namespace

CREASE_PLUGIN(Misbehaving, "test_misbehaving", "1.0.0")
