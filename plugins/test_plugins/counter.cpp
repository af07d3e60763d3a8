// Test plugin: counts its updates; the count is carried across hot-swaps (save/load_state).
// Built twice, as crease_test_counter_v1 and _v2 (COUNTER_VERSION), to swap one for the other.
// Outputs: `count` (latest TestValue), `counts` (queue of TestValue, one per update).
// Tunable: `increment` (added to `value` each update, 0..100).
#include <cstring>

#include "core/plugin.h"
#include "plugins/test_plugins/test_ports.h"

namespace {
using crease::test_plugins::TestValue;

class Counter final : public crease::Plugin {
 public:
  void configure(const crease::Params& p, crease::PortBinder& ports) override {
    increment_ = p.get_in_range<double>("increment", 1.0, 0.0, 100.0);
    ports.tunable("increment", &increment_, 0.0, 100.0);
    out_ = ports.latest_output<TestValue>("count", TestValue{});
    events_ = ports.queue_output<TestValue>("counts", 4096);
  }
  crease::Status update(const crease::Cycle& cycle) override {
    ++count_;
    value_ += increment_;
    const TestValue v{value_, count_, COUNTER_VERSION};
    out_.write(v, cycle.time_ns);
    (void)events_.try_push(v);
    return crease::Status::ok;
  }
  std::size_t save_state(std::span<std::byte> out) const noexcept override {
    if (out.size() < 2 * sizeof(double)) return SIZE_MAX;
    std::memcpy(out.data(), &count_, sizeof(count_));
    std::memcpy(out.data() + sizeof(count_), &value_, sizeof(value_));
    return sizeof(count_) + sizeof(value_);
  }
  bool load_state(std::span<const std::byte> in) noexcept override {
    if (in.size() != sizeof(count_) + sizeof(value_)) return false;
    std::memcpy(&count_, in.data(), sizeof(count_));
    std::memcpy(&value_, in.data() + sizeof(count_), sizeof(value_));
    return true;
  }
  std::string validate_param(std::string_view key, double value) override {
    if (key == "increment" && value == 13.0) return "13 is unlucky";  // lets tests see a plugin refusal
    return {};
  }

 private:
  double increment_ = 1.0;
  double value_ = 0.0;
  std::uint64_t count_ = 0;
  crease::LatestOutput<TestValue> out_;
  crease::QueueOutput<TestValue> events_;
};
}  // namespace

#define CREASE_STR2(x) #x
#define CREASE_STR(x) CREASE_STR2(x)
CREASE_PLUGIN(Counter, "test_counter", CREASE_STR(COUNTER_VERSION) ".0.0")
