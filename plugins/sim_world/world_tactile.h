// The hands' tactile sensors in the simulated world, felt through their protocols: after each
// world step the fingertips' normal forces (world_state) go through each side's sensor model
// (tactile_model.h, calibrated by the robot's YAML) to
//  - a taxel_matrix side (the right hand): a SimTactile device on a pty whose slave a symlink
//    at LINK_PATH names (drivers/host/bus_prefix.h: simulated_link_path), so that hand_driver's
//    `tactile_device` opens it and reads the samples over the serial protocol (§6) at the rate
//    it asks; the device's clock is the world's;
//  - a pst side (the left hand): that hand's pressure frames (SimHand::set_pressure), sent with
//    its next status, one sample per world step.
// Non-RT construction (throws std::runtime_error: a link path another robot holds, no pty);
// step_rt is RT.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/port_types/world_state.h"
#include "drivers/serial/serial_port.h"
#include "drivers/simdevice/sim_robot.h"
#include "drivers/simdevice/sim_tactile.h"
#include "plugins/robot_model/robot_params.h"
#include "plugins/sim_world/tactile_model.h"

namespace crease::world {

class WorldTactile {
 public:
  // LINK_PATH empty: no taxel link (the taxel side's model still runs: taxels()).
  WorldTactile(const robot::RobotParams& robot, std::uint64_t seed, const std::string& link_path);
  ~WorldTactile();  // removes the symlink
  WorldTactile(const WorldTactile&) = delete;
  WorldTactile& operator=(const WorldTactile&) = delete;

  // After a world step of DT_S: the sensors read STATE; a pst side's hand of ROBOT gets its
  // pressures; the taxel device steps at DEVICE_NS (answers Start, sends what is due). RT.
  void step_rt(const WorldState& state, double dt_s, drivers::sim::SimRobot& robot, std::int64_t device_ns) noexcept;

  // The last readings: taxels of the taxel side (kPa), PST pressures of the pst side (kPa).
  [[nodiscard]] const float (&taxels() const noexcept)[WorldHand::kFingertips][TactileModel::kTaxels] { return taxels_; }
  [[nodiscard]] const float (&pst() const noexcept)[WorldHand::kFingertips] { return pst_; }
  [[nodiscard]] const drivers::sim::SimTactile* device() const noexcept { return device_.get(); }
  [[nodiscard]] const std::string& link_path() const noexcept { return link_path_; }

 private:
  std::array<std::unique_ptr<TactileModel>, 2> model_;
  int taxel_side_ = -1, pst_side_ = -1;
  std::unique_ptr<drivers::PtyPair> pty_;
  std::unique_ptr<drivers::sim::SimTactile> device_;
  std::string link_path_;
  float taxels_[WorldHand::kFingertips][TactileModel::kTaxels] = {};
  float pst_[WorldHand::kFingertips] = {};
};

}  // namespace crease::world
