// Plugin `arm_motion`: one arm's Cartesian motions in the 1 kHz control loop, ordered after the
// drivers' update (arm_state, hand_state are this cycle's) and after the hand's contact
// controller (contact_state is this cycle's); the arm driver sends arm_command in its write.
//   inputs  arm_goal      (queue ArmGoal, core/port_types/arm_goal.h)
//           arm_state     (latest ArmState)
//           hand_state    (latest HandState: the tool frame's offset at a motion's start)
//           contact_state (latest ContactState: the stop condition)
//           sheet_state   (latest SheetState: read only when a sheet-frame goal arrives)
//           hand_control_status (latest HandControlStatus of the hand's force_controller:
//                         its retreat, an inhibit or staleness stops the arm; never written: not watched)
//   outputs arm_command   (latest ArmCommand; safe value: velocity mode, zero velocity = stay)
//           arm_motion_status (latest ArmMotionStatus)
// Parameters: arm_motion_params.h. The controller: arm_motion.h.
#include <memory>

#include "core/plugin.h"
#include "core/port_types/arm.h"
#include "core/port_types/arm_goal.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/hand_control.h"
#include "core/port_types/sheet_state.h"
#include "plugins/arm_motion/arm_motion.h"
#include "plugins/arm_motion/arm_motion_params.h"
#include "plugins/arm_motion/sheet_frame.h"

namespace {
using namespace crease;
namespace am = crease::arm_motion;

ArmCommand safe_command() {
  ArmCommand c;
  c.mode = ArmCommand::velocity;  // zero velocity: the drive stays where it is
  return c;
}

ArmMotionStatus safe_status() {
  ArmMotionStatus s;
  s.state = ArmMotionStatus::aborted;
  return s;
}

class ArmMotionPlugin final : public Plugin {
 public:
  void configure(const Params& p, PortBinder& ports) override {
    const am::ArmMotionConfig c = am::parse_arm_motion_params(p);
    model_ = std::make_unique<robot::RobotModel>(robot::RobotModel::load(c.robot_path));
    am::check_rest_posture(p, c, *model_);
    params_ = c.motion;
    motion_ = std::make_unique<am::ArmMotion>(*model_, c.side, c.motion);
    goals_ = ports.queue_input<ArmGoal>("arm_goal");
    arm_ = ports.latest_input<ArmState>("arm_state");
    hand_ = ports.latest_input<HandState>("hand_state");
    contact_ = ports.latest_input<ContactState>("contact_state");
    sheet_ = ports.latest_input<SheetState>("sheet_state");
    hand_control_ = ports.latest_input<HandControlStatus>("hand_control_status");
    command_ = ports.latest_output<ArmCommand>("arm_command", safe_command());
    status_ = ports.latest_output<ArmMotionStatus>("arm_motion_status", safe_status());
  }

  Status update(const Cycle& cycle) override {
    am::CycleInputs in;
    in.now_ns = cycle.time_ns;
    in.dt_s = static_cast<double>(cycle.period_ns) * 1e-9;
    in.arm = arm_.poll().has_data() ? &arm_.value() : nullptr;
    in.hand = hand_.poll().has_data() ? &hand_.value() : nullptr;
    in.contact = contact_.poll().has_data() ? &contact_.value() : nullptr;
    in.hand_control = hand_control_.poll().has_data() ? &hand_control_.value() : nullptr;
    ArmGoal goal;
    while (goals_.try_pop(goal)) {
      const KDL::Frame* sheet = nullptr;
      KDL::Frame world_sheet;
      // The sheet (164 kB) is copied only when a goal needs it.
      if (goal.kind != ArmGoal::stop && goal.frame == ArmGoal::sheet && sheet_.poll().has_data() &&
          static_cast<double>(cycle.time_ns - sheet_.value().timestamp_ns) * 1e-9 <=
              params_.sheet_state_max_age_s &&
          am::sheet_frame_m(sheet_.value(), world_sheet)) {
        sheet = &world_sheet;
      }
      motion_->on_goal(goal, in, sheet);
    }
    if (motion_->step(in)) command_.write(motion_->command(), cycle.time_ns);
    status_.write(motion_->status(), cycle.time_ns);
    const auto state = motion_->status().state;
    if (!motion_->state().have_cmd || state == ArmMotionStatus::aborted) return Status::degraded;
    return Status::ok;
  }

  std::size_t save_state(std::span<std::byte> out) const noexcept override { return motion_->save_state(out); }
  bool load_state(std::span<const std::byte> in) noexcept override { return motion_->load_state(in); }

 private:
  std::unique_ptr<robot::RobotModel> model_;
  std::unique_ptr<am::ArmMotion> motion_;
  am::MotionParams params_;
  QueueInput<ArmGoal> goals_;
  LatestInput<ArmState> arm_;
  LatestInput<HandState> hand_;
  LatestInput<ContactState> contact_;
  LatestInput<SheetState> sheet_;
  LatestInput<HandControlStatus> hand_control_;
  LatestOutput<ArmCommand> command_;
  LatestOutput<ArmMotionStatus> status_;
};
}  // namespace

CREASE_PLUGIN(ArmMotionPlugin, "arm_motion", "1.0.0")
