// Plugin `sim_devices`: the simulated robot's hardware for config/sim.yaml — one mocked CAN FD
// bus (broker) per device and the four devices of seed 000 answering on them: right hand
// (node 1, tactile), left hand (node 2, air-pressure sensors), right arm (node 10), left arm
// (node 11). Everything is created and started in configure (non-RT) and stopped in cleanup;
// the device threads run beside the loops like firmware beside a PC. update does nothing.
// The buses are named `<bus_prefix>-hand_r`, `-hand_l`, `-arm_r`, `-arm_l` (abstract AF_UNIX
// names: one simulated robot per prefix on a machine). List it before the driver plugins.
// Parameters: bus_prefix (default "auto": this daemon's own, drivers/host/bus_prefix.h; the
// drivers say `bus_prefix: auto` too), bitrate, data_bitrate.
#include <memory>
#include <string>
#include <vector>

#include "core/plugin.h"
#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/host/bus_prefix.h"
#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sim_arm.h"
#include "drivers/simdevice/sim_hand.h"

namespace {

using namespace crease;
namespace dr = crease::drivers;

class SimDevices final : public Plugin {
 public:
  void configure(const Params& p, PortBinder&) override {
    const std::string prefix = *dr::bus_prefix_from_params(p, std::string(dr::kAutoBusPrefix));
    const auto bitrate = static_cast<std::uint32_t>(p.get_in_range<int>("bitrate", 1'000'000, 10'000, 1'000'000));
    const auto data_bitrate =
        static_cast<std::uint32_t>(p.get_in_range<int>("data_bitrate", 5'000'000, 10'000, 8'000'000));
    auto bus = [&](const char* name, std::uint32_t node) {
      const std::string full = dr::prefixed_bus(prefix, name);
      try {
        brokers_.push_back(std::make_unique<dr::MockCanBroker>(dr::MockCanBrokerConfig{full, bitrate, data_bitrate, false}));
        buses_.push_back(std::make_unique<dr::MockCanBus>(dr::MockCanBusConfig{full, node, bitrate, data_bitrate}));
      } catch (const std::exception& e) {
        p.fail("bus_prefix", "cannot create mocked bus '" + full + "': " + e.what() +
                                 " (is another simulated robot running with this prefix?)");
      }
      return buses_.back().get();
    };
    dr::sim::SimHandConfig right;
    right.node = 1;
    dr::sim::SimHandConfig left;
    left.node = 2;
    left.pressure_sensors = true;
    dr::sim::SimArmConfig arm_r;
    arm_r.node = 10;
    dr::sim::SimArmConfig arm_l;
    arm_l.node = 11;
    dr::CanBus* b0 = bus("hand_r", right.node);
    dr::CanBus* b1 = bus("hand_l", left.node);
    dr::CanBus* b2 = bus("arm_r", arm_r.node);
    dr::CanBus* b3 = bus("arm_l", arm_l.node);
    hands_.push_back(std::make_unique<dr::sim::SimHand>(*b0, right));
    hands_.push_back(std::make_unique<dr::sim::SimHand>(*b1, left));
    arms_.push_back(std::make_unique<dr::sim::SimArm>(*b2, arm_r));
    arms_.push_back(std::make_unique<dr::sim::SimArm>(*b3, arm_l));
    dr::sim::CanopenDevice* devices[] = {hands_[0].get(), hands_[1].get(), arms_[0].get(), arms_[1].get()};
    for (std::size_t i = 0; i < 4; ++i) {
      dr::sim::CanopenDevice* d = devices[i];
      threads_.push_back(std::make_unique<dr::sim::DeviceThread>(buses_[i]->fd(), [d](std::int64_t t) { d->step(t); }));
    }
  }

  Status update(const Cycle&) override { return Status::ok; }

  void cleanup() override {
    threads_.clear();  // joins: no device steps after this
    hands_.clear();
    arms_.clear();
    buses_.clear();
    brokers_.clear();
  }

 private:
  std::vector<std::unique_ptr<dr::MockCanBroker>> brokers_;
  std::vector<std::unique_ptr<dr::MockCanBus>> buses_;
  std::vector<std::unique_ptr<dr::sim::SimHand>> hands_;
  std::vector<std::unique_ptr<dr::sim::SimArm>> arms_;
  std::vector<std::unique_ptr<dr::sim::DeviceThread>> threads_;
};

}  // namespace

CREASE_PLUGIN(SimDevices, "sim_devices", "1.0.0")
