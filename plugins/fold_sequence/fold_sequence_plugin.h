// The fold_sequence plugin: the machine (machine.h) between the control loop's ports. Ordered
// after the controllers it reads (their statuses are this cycle's) in the control loop; its
// goals are read by them in the next cycle. Declared here so that tests drive it directly on
// a PortRegistry of their own; fold_sequence_entry.cpp registers it.
//
// Ports (the plugin's names; the configuration remaps them):
//   arm_r_status, arm_l_status    latest in   crease::ArmMotionStatus  (arm_motion per arm)
//   hand_r_status, hand_l_status  latest in   crease::HandControlStatus (force_controller per hand)
//   contact_r_state, contact_l_state latest in crease::ContactState   (contact_controller per hand)
//   sheet_state                   latest in   crease::SheetState (the model's: 164 kB, copied
//                                             at most every sheet_poll_ms, and only while
//                                             folding)
//   keypoints                     latest in   crease::Keypoints (vision's: polled from the lay
//                                             on, for the fold file's flap_seen_points)
//   arm_r_goal, arm_l_goal        queue out   crease::ArmGoal
//   hand_r_goal, hand_l_goal      queue out   crease::HandGoal
//   sheet_crease                  queue out   crease::SheetCreaseEvent
//   sheet_memorize                queue out   crease::SheetMemorizeEvent
//   sequence_status               latest out  crease::SequenceStatus (creasectl status shows it)
//   target_points                 latest out  crease::TargetPoints, every kTargetPeriodNs
//                                             while any holds: the grasp point where the
//                                             pinching arm's readings put the tool while the
//                                             pinch holds the sheet (Machine::grasp_target),
//                                             the laid layer's point the fixing hand presses
//                                             where its arm's readings put that tool
//                                             (Machine::press_target); count 0 when
//                                             neither holds
// Parameters: fold (path of a sequence file, required), auto_start (false), sheet_poll_ms (200;
// must stay below the file's sheet_max_age_s less the model's period). Tunable `command`
// (0..5, integers): 1 start, 2 pause, 3 resume, 4 abort, 5 step; read once and reset to 0 by
// the plugin (`creasectl sequence start|pause|resume|abort|step` sets it).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "core/plugin.h"
#include "core/port.h"
#include "core/port_types/sheet_state.h"
#include "plugins/fold_sequence/fold_spec.h"
#include "plugins/fold_sequence/machine.h"

namespace crease::fold {

class FoldSequencePlugin final : public Plugin {
 public:
  // A queue's writer and reader must agree on its capacity: force_controller reads hand_goal
  // with 16 records (its kGoalQueue); arm_motion and sheet_model read with the default.
  static constexpr std::size_t kHandGoalQueue = 16;

  void configure(const Params& p, PortBinder& ports) override;
  void activate() override;
  Status update(const Cycle& c) override;
  std::size_t save_state(std::span<std::byte> out) const noexcept override;
  bool load_state(std::span<const std::byte> in) noexcept override;
  std::string validate_param(std::string_view key, double value) override;

  [[nodiscard]] const Machine& machine() const noexcept { return *machine_; }
  [[nodiscard]] const FoldSpec& spec() const noexcept { return spec_; }

 private:
  // RT. Logs what the abort's retreat did this cycle (Outbox's retried, joints_park, gave_up).
  void log_retreat(const Outbox& out) const noexcept;
  // RT. The machine's targets (grasp, press) onto target_points.
  void write_targets(const Sensing& in, std::int64_t now_ns) noexcept;
  FoldSpec spec_;
  std::unique_ptr<Machine> machine_;
  std::unique_ptr<Outbox> outbox_;
  bool auto_start_ = false;
  bool started_ = false;
  std::int64_t sheet_poll_ns_ = 200'000'000;
  std::int64_t sheet_polled_ns_ = 0;  // the cycle time of the last poll of sheet_state (0: never)
  double command_ = 0;  // the tunable: a Command, 0 when none is waiting
  std::uint32_t logged_transitions_ = 0;
  LatestInput<ArmMotionStatus> arm_status_[2];
  LatestInput<HandControlStatus> hand_status_[2];
  LatestInput<ContactState> contact_[2];
  LatestInput<SheetState> sheet_;
  LatestInput<Keypoints>
      keypoints_;  // optional: unbound, the laid layer is judged by the model alone
  QueueOutput<ArmGoal> arm_goal_[2];
  QueueOutput<HandGoal> hand_goal_[2];
  QueueOutput<SheetCreaseEvent> crease_;
  QueueOutput<SheetMemorizeEvent> memorize_;
  LatestOutput<SequenceStatus> status_;
  LatestOutput<TargetPoints> target_;
  std::unique_ptr<TargetPoints> target_value_;  // 20 kB: not on the stack
  std::int64_t target_written_ns_ = 0;
  std::uint32_t targets_on_ = 0;                               // how many the last write carried
  static constexpr std::int64_t kTargetPeriodNs = 10'000'000;  // 100 Hz: the model runs at 60
  SequenceStatus status_value_{};
};

}  // namespace crease::fold
