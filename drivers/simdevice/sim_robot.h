// SimRobot: the simulated robot's hardware of seed 000 on one machine: one mocked CAN FD bus
// (broker) per device, named `<prefix>-hand_r`, `-hand_l`, `-arm_r`, `-arm_l`, and the devices
// answering on them: right hand (node 1), left hand with air-pressure sensors (node 2), right
// arm (node 10), left arm (node 11). Who steps the devices is the owner's choice: device threads
// beside the loops (plugins/sim_devices), or a simulated world stepping them in lockstep with
// its physics (plugins/sim_world). Construction and destruction are non-RT; step_rt is RT.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "drivers/can/mock_can_broker.h"
#include "drivers/can/mock_can_bus.h"
#include "drivers/simdevice/sim_arm.h"
#include "drivers/simdevice/sim_hand.h"

namespace crease::drivers::sim {

struct SimRobotConfig {
  std::string prefix;                      // bus names: <prefix>-hand_r, ...
  std::uint32_t bitrate = 1'000'000;       // arbitration phase, bit/s
  std::uint32_t data_bitrate = 5'000'000;  // FD data phase, bit/s
  bool hand_external_positions = false;    // SimHandConfig::external_positions of both hands
  // Every device's command watchdog (ns of its clock without a valid command: safe state or quick
  // stop; SimHandConfig / SimArmConfig::watchdog_ns).
  std::int64_t watchdog_ns = 20'000'000;
  // The arms' joint angles at power-up (rad): right, left.
  std::array<std::array<float, arm::kJoints>, 2> arm_initial_rad{};
};

class SimRobot {
 public:
  static constexpr int kDevices = 4;  // hand_r, hand_l, arm_r, arm_l: the order of bus(i)
  static constexpr const char* kBusNames[kDevices] = {"hand_r", "hand_l", "arm_r", "arm_l"};

  // Throws std::runtime_error naming the bus when one cannot be created (the name is taken).
  explicit SimRobot(const SimRobotConfig& cfg);
  ~SimRobot();
  SimRobot(const SimRobot&) = delete;
  SimRobot& operator=(const SimRobot&) = delete;

  // Index 0: right, 1: left (robot::Side's order).
  [[nodiscard]] SimHand& hand(int side) noexcept { return *hands_[side]; }
  [[nodiscard]] SimArm& arm(int side) noexcept { return *arms_[side]; }
  [[nodiscard]] CanopenDevice& device(int i) noexcept;
  [[nodiscard]] MockCanBus& bus(int i) noexcept { return *buses_[i]; }
  [[nodiscard]] MockCanBroker& broker(int i) noexcept { return *brokers_[i]; }
  // Steps every device at now_ns (its frames received, SYNCs answered, watchdogs run). RT.
  void step_rt(std::int64_t now_ns) noexcept;

 private:
  std::array<std::unique_ptr<MockCanBroker>, kDevices> brokers_;
  std::array<std::unique_ptr<MockCanBus>, kDevices> buses_;
  std::array<std::unique_ptr<SimHand>, 2> hands_;
  std::array<std::unique_ptr<SimArm>, 2> arms_;
};

}  // namespace crease::drivers::sim
