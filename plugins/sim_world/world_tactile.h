// The hands' tactile sensors in the simulated world, felt through their protocols: after each
// world step the fingertips' normal forces (world_state) go through each side's sensor model
// (tactile_model.h, calibrated by the robot's YAML) to
//  - a taxel_matrix side (the right hand): a SimTactile device on a Unix stream socket that
//    listens at LINK_PATH (drivers/host/bus_prefix.h: simulated_link_path;
//    drivers/serial/unix_link.h: why not a pty), so that hand_driver's `tactile_device`
//    connects and reads the samples over the serial protocol (§6) at the rate it asks; the
//    device's clock is the world's. One connection at a time, the next waiting one once it
//    hangs up (a hot-swapped driver's); each starts silent until its Start;
//  - a pst side (the left hand): that hand's pressure frames (SimHand::set_pressure), sent with
//    its next status, one sample per world step.
// Non-RT construction (throws std::runtime_error: a link path another robot holds, no socket);
// step_rt is RT.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/port_types/world_state.h"
#include "drivers/serial/unix_link.h"
#include "drivers/simdevice/sim_robot.h"
#include "drivers/simdevice/sim_tactile.h"
#include "plugins/robot_model/robot_params.h"
#include "plugins/sim_world/tactile_model.h"

namespace crease::world {

class WorldTactile {
 public:
  // LINK_PATH empty: no taxel link (the taxel side's model still runs: taxels()).
  WorldTactile(const robot::RobotParams& robot, std::uint64_t seed, const std::string& link_path);
  ~WorldTactile();  // closes the connection, removes the link
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
  // Any thread: connections served so far.
  [[nodiscard]] std::uint64_t connections() const noexcept { return connections_.load(std::memory_order_relaxed); }

 private:
  std::array<std::unique_ptr<TactileModel>, 2> model_;
  int taxel_side_ = -1, pst_side_ = -1;
  std::unique_ptr<drivers::UnixLinkListener> listener_;
  std::unique_ptr<drivers::sim::SimTactile> device_;
  int peer_ = -1;             // the connection served, or -1
  std::uint32_t steps_ = 0;
  std::atomic<std::uint64_t> connections_{0};
  std::string link_path_;
  float taxels_[WorldHand::kFingertips][TactileModel::kTaxels] = {};
  float pst_[WorldHand::kFingertips] = {};
};

}  // namespace crease::world
