// crease-bench control's hand stage: both hands' contact controller (C_contact, Eq. 5:
// contact::ContactDetector) and command stage (force::HandController: posture, hold, C_force Eq. 6),
// what the plugins' updates run, on synthetic hands (a first finger pressing a spring: the
// joints give under the force at the commanded stiffness; the right hand's taxels, the left
// hand's PST sensors read the force). Each hand cycles through settling (the detector arms), a
// descent onto the spring at 20 mm/s stopped on the detected contact, a ramped force goal
// (0.5 N, then 2 N) held under C_force, and a posture goal that lifts off; the stage's step is
// what the bench times, the plant is not.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/hand_control.h"
#include "core/port_types/hand_goal.h"
#include "core/port_types/tactile.h"
#include "plugins/contact_controller/contact_detector.h"
#include "plugins/force_controller/hand_controller.h"
#include "plugins/robot_model/robot_layout.h"

namespace crease::bench {

class BenchHand {
 public:
  // ROBOT_YAML: config/robot/crease_robot.yaml (the force controller's calibration and limits).
  BenchHand(robot::Side side, const std::string& robot_yaml);

  // Before the timed step: the plant's sensors at NOW, and the goal this cycle's script sends.
  void sense(std::int64_t now_ns);
  // The timed part: what contact_controller's and force_controller's updates compute.
  void step() noexcept;
  // After it: the plant follows the command; the script moves on.
  void follow();

  [[nodiscard]] std::uint64_t onsets() const noexcept { return contact_.onsets; }
  [[nodiscard]] std::uint64_t force_goals() const noexcept { return force_goals_; }
  [[nodiscard]] std::uint64_t settled_holds() const noexcept { return settled_; }
  [[nodiscard]] double max_force_n() const noexcept { return max_force_n_; }

 private:
  [[nodiscard]] double plant_force_n() const noexcept;

  bool taxels_;
  std::unique_ptr<contact::ContactDetector> detector_;
  std::unique_ptr<force::HandController> controller_;
  HandState hand_{};
  Tactile tactile_{};
  HandCommand command_{};
  ContactState contact_{};
  ContactEvent event_{};
  HandControlStatus status_{};
  HandGoal goal_{};
  bool goal_due_ = false, commanded_ = false;
  std::int64_t now_ns_ = 0;
  std::array<float, HandState::kJoints> relaxed_{};  // the hand's posture at no load
  double descent_mm_ = -2.0;  // the fingertip's depth past the spring's surface (the arm's travel)
  bool descending_ = false;
  int phase_ = 0, phase_cycles_ = 0;
  std::uint64_t force_goals_ = 0, settled_ = 0;
  double max_force_n_ = 0;
};

}  // namespace crease::bench
