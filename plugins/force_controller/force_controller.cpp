// force_controller: one hand's command stage in the control loop, the ONE writer of its
// `hand_command`: posture, hold and force (C_force, seed 000 Eq. 6) modes from `hand_goal`
// goals, retreat as its safe action (hand_controller.h). Ordered after the hand's driver and
// its contact controller; reads hand_state, tactile (right hand) and contact_state; writes
// hand_command, hand_control_status and hand_control_event. README.md.
#include <cstring>

#include "core/plugin.h"
#include "core/port_types/contact.h"
#include "core/port_types/hand.h"
#include "core/port_types/hand_control.h"
#include "core/port_types/hand_goal.h"
#include "core/port_types/tactile.h"
#include "plugins/force_controller/force_params.h"
#include "plugins/force_controller/hand_controller.h"

namespace crease::force {
namespace {

// What a hot-swap carries: a version tag, then the controller's state.
struct Saved {
  std::uint32_t magic = 0x46435331;  // "FCS1"
  std::uint32_t size = sizeof(HandController::State);
  HandController::State state;
};

class ForceController final : public Plugin {
 public:
  static constexpr std::size_t kGoalQueue = 16;   // goals: a few per motion
  static constexpr std::size_t kEventQueue = 64;

  void configure(const Params& p, PortBinder& ports) override {
    controller_ = HandController(read_force_config(p));
    ports.tunable("k_p", &k_p_, 0.0, 100.0);
    k_p_ = controller_.config().k_p;
    hand_ = ports.latest_input<HandState>("hand_state");
    if (controller_.config().sensor == robot::TactileKind::taxel_matrix) tactile_ = ports.latest_input<Tactile>("tactile");
    contact_ = ports.latest_input<ContactState>("contact_state");
    goals_ = ports.queue_input<HandGoal>("hand_goal", kGoalQueue);
    // The safe value: enable 0, the hand holds its position with zero force (drivers/README.md §3).
    command_ = ports.latest_output<HandCommand>("hand_command", HandCommand{});
    status_ = ports.latest_output<HandControlStatus>("hand_control_status", HandControlStatus{});
    events_ = ports.queue_output<HandControlEvent>("hand_control_event", kEventQueue);
  }

  Status update(const Cycle& c) override {
    const auto info = hand_.poll();
    ForceInputs in;
    in.time_ns = c.time_ns;
    in.dt_s = static_cast<double>(c.period_ns) * 1e-9;
    in.hand = info.has_data() ? &hand_.value() : nullptr;
    in.hand_new = info.is_new();
    if (tactile_.bound() && tactile_.poll().has_data()) in.tactile = &tactile_.value();
    if (contact_.poll().has_data()) in.contact = &contact_.value();
    controller_.set_k_p(k_p_);
    HandGoal g;
    while (goals_.try_pop(g)) (void)controller_.submit_rt(g, in);
    HandCommand cmd;
    HandControlStatus st;
    const bool commanding = controller_.step_rt(in, cmd, st);
    for (const HandControlEvent& e : controller_.events()) {
      if (!events_.try_push(e)) ++events_dropped_;
      if (e.kind == HandControlEvent::force_limit_fault) {
        static constexpr const char* kWhat[kFingers] = {
            "force limit: ff measured over force_limit_n (mN), retreat", "force limit: mf measured over force_limit_n (mN), retreat",
            "force limit: rf measured over force_limit_n (mN), retreat", "force limit: lf measured over force_limit_n (mN), retreat",
            "force limit: th measured over force_limit_n (mN), retreat"};
        log_rt(rt::LogLevel::warn, kWhat[e.finger < kFingers ? e.finger : 0], static_cast<std::int64_t>(e.value * 1000.0f));
      }
    }
    controller_.clear_events();
    if (commanding) command_.write(cmd, c.time_ns);
    status_.write(st, c.time_ns);
    return st.inhibit == HandInhibit::none && commanding ? Status::ok : Status::degraded;
  }

  std::size_t save_state(std::span<std::byte> out) const noexcept override {
    Saved s;
    s.state = controller_.state();
    if (out.size() < sizeof(s)) return SIZE_MAX;
    std::memcpy(out.data(), &s, sizeof(s));
    return sizeof(s);
  }
  bool load_state(std::span<const std::byte> in) noexcept override {
    Saved s;
    if (in.size() != sizeof(s)) return false;
    std::memcpy(&s, in.data(), sizeof(s));
    if (s.magic != Saved{}.magic || s.size != sizeof(HandController::State)) return false;
    controller_.restore(s.state);
    return true;
  }

 private:
  HandController controller_{ForceConfig{}};
  double k_p_ = 0;
  LatestInput<HandState> hand_;
  LatestInput<Tactile> tactile_;
  LatestInput<ContactState> contact_;
  QueueInput<HandGoal> goals_;
  LatestOutput<HandCommand> command_;
  LatestOutput<HandControlStatus> status_;
  QueueOutput<HandControlEvent> events_;
  std::uint64_t events_dropped_ = 0;
};

}  // namespace
}  // namespace crease::force

CREASE_PLUGIN(crease::force::ForceController, "force_controller", "1.0.0")
