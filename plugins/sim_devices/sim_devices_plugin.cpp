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
#include "drivers/host/bus_prefix.h"
#include "drivers/simdevice/device_thread.h"
#include "drivers/simdevice/sim_robot.h"

namespace {

using namespace crease;
namespace dr = crease::drivers;

class SimDevices final : public Plugin {
 public:
  void configure(const Params& p, PortBinder&) override {
    dr::sim::SimRobotConfig cfg;
    cfg.prefix = *dr::bus_prefix_from_params(p, std::string(dr::kAutoBusPrefix));
    cfg.bitrate = static_cast<std::uint32_t>(p.get_in_range<int>("bitrate", 1'000'000, 10'000, 1'000'000));
    cfg.data_bitrate = static_cast<std::uint32_t>(p.get_in_range<int>("data_bitrate", 5'000'000, 10'000, 8'000'000));
    try {
      robot_ = std::make_unique<dr::sim::SimRobot>(cfg);
    } catch (const std::exception& e) {
      p.fail("bus_prefix", std::string("cannot create the mocked buses: ") + e.what() +
                               " (is another simulated robot running with this prefix?)");
    }
    for (int i = 0; i < dr::sim::SimRobot::kDevices; ++i) {
      dr::sim::CanopenDevice* d = &robot_->device(i);
      threads_.push_back(std::make_unique<dr::sim::DeviceThread>(robot_->bus(i).fd(), [d](std::int64_t t) { d->step(t); }));
    }
  }

  Status update(const Cycle&) override { return Status::ok; }

  void cleanup() override {
    threads_.clear();  // joins: no device steps after this
    robot_.reset();
  }

 private:
  std::unique_ptr<dr::sim::SimRobot> robot_;
  std::vector<std::unique_ptr<dr::sim::DeviceThread>> threads_;
};

}  // namespace

CREASE_PLUGIN(SimDevices, "sim_devices", "1.0.0")
