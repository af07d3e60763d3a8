#include "drivers/simdevice/sim_robot.h"

#include <stdexcept>

namespace crease::drivers::sim {

SimRobot::SimRobot(const SimRobotConfig& cfg) {
  const std::uint8_t nodes[kDevices] = {1, 2, 10, 11};
  for (int i = 0; i < kDevices; ++i) {
    const std::string full = cfg.prefix + "-" + kBusNames[i];
    brokers_[i] = std::make_unique<MockCanBroker>(MockCanBrokerConfig{full, cfg.bitrate, cfg.data_bitrate, false});
    buses_[i] = std::make_unique<MockCanBus>(MockCanBusConfig{full, nodes[i], cfg.bitrate, cfg.data_bitrate});
  }
  for (int s = 0; s < 2; ++s) {
    SimHandConfig h;
    h.node = nodes[s];
    h.pressure_sensors = s == 1;  // the left hand's air-pressure sensors
    h.external_positions = cfg.hand_external_positions;
    h.watchdog_ns = cfg.watchdog_ns;
    hands_[s] = std::make_unique<SimHand>(*buses_[s], h);
    SimArmConfig a;
    a.node = nodes[2 + s];
    a.watchdog_ns = cfg.watchdog_ns;
    for (int j = 0; j < arm::kJoints; ++j) a.initial_position_rad[j] = cfg.arm_initial_rad[s][j];
    arms_[s] = std::make_unique<SimArm>(*buses_[2 + s], a);
  }
}

SimRobot::~SimRobot() {
  // Devices before their buses, buses before their brokers.
  for (auto& h : hands_) h.reset();
  for (auto& a : arms_) a.reset();
  for (auto& b : buses_) b.reset();
  for (auto& b : brokers_) b.reset();
}

CanopenDevice& SimRobot::device(int i) noexcept {
  if (i < 2) return *hands_[i];
  return *arms_[i - 2];
}

void SimRobot::step_rt(std::int64_t now_ns) noexcept {
  for (int i = 0; i < kDevices; ++i) device(i).step(now_ns);
}

}  // namespace crease::drivers::sim
