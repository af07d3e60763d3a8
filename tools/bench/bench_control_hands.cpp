#include "bench_control_hands.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>

#include "core/params.h"
#include "plugins/contact_controller/contact_params.h"
#include "plugins/force_controller/force_params.h"

namespace crease::bench {
namespace {

constexpr int FFJ3 = 3, FFJ2 = 4;
constexpr double kLeverM = 0.09;         // fingertip force -> FFJ3 torque (m): about the index's
constexpr double kSpringNPerMm = 0.2;    // the surface pressed (N per mm)
constexpr double kDescentMmPerCycle = 0.02;  // 20 mm/s

contact::ContactConfig contact_config(bool taxels) {
  // config/sim.yaml's contact_r and contact_l.
  const std::string y = taxels ? "{tactile: taxels, tactile_enter_kpa: 8, tactile_exit_kpa: 4, enter_rad: 0.00005, "
                                 "exit_rad: 0.00003}"
                               : "{tactile: pst}";
  return contact::read_contact_config(Params(YAML::Load(y), "bench.yaml", "contact.params"));
}

force::ForceConfig force_config(robot::Side side, const std::string& robot_yaml) {
  const std::string y = std::string("{side: ") + (side == robot::Side::right ? "right" : "left") + ", robot: " +
                        robot_yaml + ", start: hold, default_stiffness: 6}";
  return force::read_force_config(Params(YAML::Load(y), "bench.yaml", "force.params"));
}

}  // namespace

BenchHand::BenchHand(robot::Side side, const std::string& robot_yaml)
    : taxels_(side == robot::Side::right),
      detector_(std::make_unique<contact::ContactDetector>(contact_config(taxels_))),
      controller_(std::make_unique<force::HandController>(force_config(side, robot_yaml))) {
  for (int j = 0; j < HandState::kJoints; ++j) relaxed_[static_cast<std::size_t>(j)] = 0.2f;
  hand_.valid = (1u << 20) - 1;
  hand_.fresh = 1;
  hand_.health = DeviceHealth::ok;
  hand_.pressure_valid = taxels_ ? 0 : 0x1F;
  tactile_.valid = 0x1F;
  tactile_.health = DeviceHealth::ok;
  tactile_.fresh = 1;
}

double BenchHand::plant_force_n() const noexcept {
  // The fingertip at the arm's depth, pulled in further by the finger's commanded flexion, the
  // spring against the joint's stiffness in series (quasi-static).
  const double k_joint = commanded_ ? std::max(0.1, static_cast<double>(command_.stiffness_nm_per_rad[FFJ3])) : 6.0;
  const double flex = commanded_ ? (command_.target_rad[FFJ3] - relaxed_[FFJ3]) + 0.4 * (command_.target_rad[FFJ2] - relaxed_[FFJ2])
                                 : 0.0;
  const double depth_mm = descent_mm_ + 1000.0 * kLeverM * flex;
  if (depth_mm <= 0) return 0;
  const double finger_mm_per_n = 1000.0 * kLeverM * kLeverM / k_joint;  // compliance at the tip
  return depth_mm / (1.0 / kSpringNPerMm + finger_mm_per_n);
}

void BenchHand::sense(std::int64_t now_ns) {
  now_ns_ = now_ns;
  const double f = plant_force_n();
  max_force_n_ = std::max(max_force_n_, f);
  const double k_joint = commanded_ ? std::max(0.1, static_cast<double>(command_.stiffness_nm_per_rad[FFJ3])) : 6.0;
  for (int j = 0; j < HandState::kJoints; ++j)
    hand_.position_rad[j] = commanded_ ? command_.target_rad[j] : relaxed_[static_cast<std::size_t>(j)];
  hand_.position_rad[FFJ3] -= static_cast<float>(f * kLeverM / k_joint);  // the joint gives
  hand_.position_rad[FFJ3] = std::round(hand_.position_rad[FFJ3] * 1e4f) * 1e-4f;  // the wire's unit
  hand_.timestamp_ns = now_ns;
  for (int t = 0; t < HandState::kPressureSensors; ++t) hand_.pressure_kpa[t] = 0.3f;
  hand_.pressure_kpa[0] = static_cast<float>(0.3 + 10.0 * f);  // PST: 10 kPa per N
  tactile_.timestamp_ns = now_ns;
  for (auto& tip : tactile_.pressure_kpa)
    for (float& p : tip) p = 0;
  const float per_taxel = static_cast<float>(f * 1000.0 / 11.0 / 4.0);  // four taxels, 11 mm^2 each
  if (per_taxel >= 8.0f)
    for (int k : {14, 15, 20, 21}) tactile_.pressure_kpa[0][k] = per_taxel;
  // The script: every phase a goal or a motion.
  ++phase_cycles_;
  goal_due_ = false;
  goal_ = HandGoal{};
  switch (phase_) {
    case 0:  // settle: the detector arms
      if (contact_.armed != 0 && phase_cycles_ > 20) phase_ = 1, phase_cycles_ = 0, descending_ = true;
      break;
    case 1:  // descend until the contact is reported
      if (contact_.in_contact != 0) {
        descending_ = false;
        goal_.mode = HandMode::force;
        goal_.force_n = force_goals_ % 2 == 0 ? 0.5f : 2.0f;
        goal_.ramp_s = 0.1f;
        goal_.fingers = 1;
        goal_due_ = true;
        ++force_goals_;
        phase_ = 2, phase_cycles_ = 0;
      } else if (phase_cycles_ > 3000) {
        phase_ = 3, phase_cycles_ = 0;  // never touched: lift anyway
      }
      break;
    case 2:  // C_force holds
      if (phase_cycles_ == 800) {
        settled_ += status_.settled;
        goal_.mode = HandMode::posture;
        for (int j = 0; j < HandGoal::kJoints; ++j) goal_.target_rad[j] = relaxed_[static_cast<std::size_t>(j)];
        goal_.ramp_s = 0.1f;
        goal_due_ = true;
        phase_ = 3, phase_cycles_ = 0;
      }
      break;
    default:  // lift off and settle anew
      descent_mm_ = std::max(-2.0, descent_mm_ - 0.05);
      if (phase_cycles_ > 300) phase_ = 0, phase_cycles_ = 0;
      break;
  }
}

void BenchHand::step() noexcept {
  contact::ContactInputs ci;
  ci.time_ns = now_ns_;
  ci.hand = &hand_;
  ci.hand_new = true;
  ci.command = commanded_ ? &command_ : nullptr;
  ci.tactile = taxels_ ? &tactile_ : nullptr;
  (void)detector_->step_rt(ci, contact_, event_);
  force::ForceInputs fi;
  fi.time_ns = now_ns_;
  fi.hand = &hand_;
  fi.hand_new = true;
  fi.tactile = taxels_ ? &tactile_ : nullptr;
  fi.contact = &contact_;
  if (goal_due_) (void)controller_->submit_rt(goal_, fi);
  commanded_ = controller_->step_rt(fi, command_, status_) || commanded_;
  controller_->clear_events();
}

void BenchHand::follow() {
  if (descending_) descent_mm_ += kDescentMmPerCycle;
}

}  // namespace crease::bench
