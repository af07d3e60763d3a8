// The simulated world's physics (plugins/sim_world): the robot of config/robot/ (two
// position-controlled arms, two hands of compliant joints) and a physical sheet on the table.
//
//   World w(robot_model, params);          // configure time: allocates, throws ConfigError
//   w.command_arm_rt(Side::right, q);      // any time: the newest commands win
//   w.command_hand_rt(Side::right, target, stiffness);
//   w.step_rt();                           // one step of params.dt_s (1 ms): RT
//   const WorldState& s = w.state();       // fingertips, forces, joint angles, counters
//
// One step: the commands are checked (non-finite targets refused, targets clamped to the
// URDF's limits, motions slowed to its velocity limits; negative or non-finite stiffness
// refused; each counted); the arms' links move kinematically to the commanded angles, the
// hands' joints settle quasi-statically (hand_compliance.h) against what they touch where the
// new commands put them (the sheet as the last step left it, the table) and the friction they
// felt in the last step; then the sheet (its own XPBD instance, params.sheet) steps with the
// robot's shapes, moving smoothly from their last poses to the settled ones, as contacts solved
// in each of its substeps (finger_contacts.h).
// A step that leaves anything non-finite is rolled back (sheet positions and link state, the
// hands' deflections) and counted. Same parameters, seed and commands: bit-identical steps.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/port_types/sheet_state.h"
#include "core/port_types/world_state.h"
#include "plugins/robot_model/robot_model.h"
#include "plugins/sheet_model/collision_world.h"
#include "plugins/sheet_model/xpbd_sheet.h"
#include "plugins/sim_world/finger_contacts.h"
#include "plugins/sim_world/hand_compliance.h"
#include "plugins/sim_world/randomise.h"
#include "plugins/sim_world/robot_shapes.h"
#include "plugins/sim_world/side_kinematics.h"
#include "plugins/sim_world/thumb_contacts.h"
#include "plugins/sim_world/world_params.h"

namespace crease::world {

using robot::Side;

class World {
 public:
  using ArmJoints = std::array<double, robot::kArmJoints>;
  using HandJoints = std::array<double, robot::kHandJoints>;

  // Non-RT. MODEL must outlive the world. Throws crease::ConfigError or std::invalid_argument.
  World(const robot::RobotModel& model, const WorldParams& params);
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // Commands, applied at the next step (RT). Angles rad, stiffness N m/rad, drivers' orders.
  void command_arm_rt(Side s, std::span<const double, robot::kArmJoints> q_rad) noexcept;
  void command_hand_rt(Side s, std::span<const double, robot::kHandJoints> target_rad,
                       std::span<const double, robot::kHandJoints> stiffness_nm_per_rad) noexcept;

  void step_rt() noexcept;

  [[nodiscard]] const WorldState& state() const noexcept { return state_; }
  // The sheet as the `sheet_truth` payload (SheetState). RT.
  void export_sheet_rt(SheetState& out) noexcept;

  // Inspection (tests, benchmark).
  [[nodiscard]] const sheet::XpbdSheet& sheet() const noexcept { return *sheet_; }
  [[nodiscard]] sheet::XpbdSheet& sheet() noexcept { return *sheet_; }
  [[nodiscard]] const WorldDraws& draws() const noexcept { return draws_; }
  [[nodiscard]] const WorldParams& params() const noexcept { return params_; }
  [[nodiscard]] const std::vector<WorldShape>& shapes() const noexcept { return shapes_; }
  [[nodiscard]] const FingerContacts& contacts() const noexcept { return contacts_; }
  [[nodiscard]] const SideKinematics& kinematics(Side s) const noexcept { return *kin_[index(s)]; }
  // The applied (checked) arm angles and hand targets, and the hand's joint angles.
  [[nodiscard]] const ArmJoints& arm_angles(Side s) const noexcept { return hand_[index(s)].arm; }
  [[nodiscard]] const HandJoints& hand_targets(Side s) const noexcept { return hand_[index(s)].target; }
  [[nodiscard]] const HandJoints& hand_angles(Side s) const noexcept { return hand_[index(s)].angles; }
  [[nodiscard]] const HandJoints& hand_deflection(Side s) const noexcept { return hand_[index(s)].deflection; }
  [[nodiscard]] const HandJoints& hand_stiffness(Side s) const noexcept { return hand_[index(s)].stiffness; }
  // Worst depth (mm) of any hand shape in the sheet (beyond the covers' surface, i.e. into
  // the sheet's half thickness) or below the table, at the end of the last step, as the
  // contacts measured it.
  [[nodiscard]] double max_penetration_mm() const noexcept { return max_penetration_mm_; }
  // The same from the geometry alone, whether the contacts are on or not: every shape of the
  // hands against every node (half the thickness from its centre) and the table top (tests).
  [[nodiscard]] double geometric_penetration_mm() const noexcept;
  // The contacts side S settled against this step (hand_compliance.h), the shape of each (and
  // the second shape of a pinch, else -1), and each one's normal force (N).
  struct Settled {
    std::span<const HandCompliance::Contact> contacts;
    std::span<const int> shape, shape2;
    std::span<const double> force_n;
  };
  [[nodiscard]] Settled settled(Side s) const noexcept {
    const int i = index(s), n = n_settled_[i];
    return {{hand_contacts_[i].data(), std::size_t(n)}, {hand_contact_shape_[i].data(), std::size_t(n)},
            {hand_contact_shape2_[i].data(), std::size_t(n)}, {hand_contact_force_[i].data(), std::size_t(n)}};
  }
  // The world's time, s.
  [[nodiscard]] double time_s() const noexcept { return state_.time_s; }
  // Test seam: the next step ends non-finite (as a physics blow-up would), to be rolled back.
  void poison_next_step_for_test() noexcept { poison_ = true; }

 private:
  struct HandSim {
    ArmJoints arm{};            // applied arm angles
    ArmJoints arm_cmd{};        // newest command
    HandJoints target{};        // applied hand targets (checked)
    HandJoints target_cmd{};
    HandJoints stiffness{};     // accepted stiffness
    HandJoints stiffness_cmd{};
    HandJoints deflection{};    // angle - target, from the last step
    HandJoints angles{};        // target + deflection, within limits
    HandJoints tau_external{};  // N mm on the joints besides the contacts: none yet
    ArmJoints arm_lo{}, arm_hi{}, arm_vmax{};
    HandJoints hand_lo{}, hand_hi{}, hand_vmax{};
    int tip_link[robot::kFingertips] = {};
  };
  static constexpr int index(Side s) noexcept { return static_cast<int>(s); }

  void apply_commands_rt(HandSim& h) noexcept;
  void pose_hands_rt() noexcept;
  void settle_hand_rt(int side) noexcept;
  void measure_penetration_rt() noexcept;
  [[nodiscard]] bool over_table(Vec3 p) const noexcept;  // within the table top's extent in x, y
  void fill_state_rt() noexcept;
  void add_table_slab();  // configure time: the sheet's table with edges

  WorldParams params_;
  WorldDraws draws_;
  std::unique_ptr<sheet::XpbdSheet> sheet_;
  sheet::CollisionWorld table_;
  std::array<std::unique_ptr<SideKinematics>, robot::kSides> kin_;
  std::array<const SideKinematics*, robot::kSides> kin_view_{};
  std::vector<WorldShape> shapes_;
  std::vector<Pose> pose_pre_;     // per shape: where the new commands put it with the last deflection
  std::vector<Pose> pose_target_;  // per shape: where the commanded targets alone put it
  FingerContacts contacts_;
  ThumbContacts thumb_contacts_;
  std::array<HandSim, robot::kSides> hand_;
  std::array<std::unique_ptr<HandCompliance>, robot::kSides> compliance_;
  // Per side, this step: the contacts the hand settled against, their shapes and forces (N).
  std::array<std::vector<HandCompliance::Contact>, robot::kSides> hand_contacts_;
  std::array<std::vector<int>, robot::kSides> hand_contact_shape_, hand_contact_shape2_;
  std::array<std::vector<double>, robot::kSides> hand_contact_force_;
  std::array<int, robot::kSides> n_settled_{};
  std::vector<double> shape_normal_n_;  // per shape: its normal load after the settle (N)
  std::vector<Vec3> shape_normal_vec_n_;
  std::vector<sheet::Vec3> last_good_, normals_;
  std::vector<double> strain_;
  WorldState state_;
  double max_penetration_mm_ = 0;
  bool poison_ = false;
};

}  // namespace crease::world
